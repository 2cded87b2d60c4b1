"""Writers that fill the cache at once (a campaign's workers on a fresh machine) each leave a whole table and
never fail on one another's temporary (startrack.base.cache_dir.publish_file, publish_folder)."""

from concurrent.futures import ThreadPoolExecutor

import numpy as np

from startrack.base.cache_dir import publish_file, publish_folder

WRITERS, WRITES = 6, 15


def _hammer(write):
    with ThreadPoolExecutor(WRITERS) as pool:
        for future in [pool.submit(write, w) for w in range(WRITERS) for _ in range(WRITES)]:
            future.result()  # re-raises a writer's failure


def test_concurrent_writers_of_one_file_leave_one_whole_file(tmp_path):
    path = tmp_path / "table.npz"
    _hammer(lambda w: publish_file(path, lambda temporary: np.savez(temporary, values=np.full(200_000, w))))
    with np.load(path) as data:
        values = data["values"]
    assert values.size == 200_000 and np.all(values == values[0])  # one writer's table, whole
    assert [p.name for p in tmp_path.iterdir()] == ["table.npz"]  # no temporary left behind


def test_concurrent_writers_of_one_folder_leave_one_whole_folder(tmp_path):
    folder = tmp_path / "catalog"

    def write(w):
        def fill(temporary):
            np.save(temporary / "a.npy", np.full(50_000, w))
            np.save(temporary / "b.npy", np.full(50_000, w))
        publish_folder(folder, fill)

    _hammer(write)
    a, b = np.load(folder / "a.npy"), np.load(folder / "b.npy")
    assert np.all(a == a[0]) and np.all(b == a[0])
    assert [p.name for p in tmp_path.iterdir()] == ["catalog"]
