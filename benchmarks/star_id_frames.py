"""Seeded star-identification frames shared by every solver of ``benchmarks/star_id.py``.

Sensor (issue 6, "Benchmark against peers"): ideal pinhole, 16 deg across a 1024 x 1024 image
(rectangular field, principal point at the image centre), stars with V <= 6.0 from Hipparcos-2
propagated to J2000.0 (:func:`startrack.catalog.hipparcos.load_star_catalog`), centroid noise 0.1 px
per axis (Gaussian, independent).

Per frame: a uniformly random attitude q_IS; every catalogue star whose image falls on the sensor
is projected (:class:`startrack.camera.model.Camera`).  Star images closer than ``BLEND_RADIUS_PX``
merge into one centroid (a real centroider cannot split them; Hipparcos has ~30 such pairs with
V <= 6, e.g. alpha Centauri A/B): flux-weighted mean position, summed flux, truth HIP of the
brightest member, the other members listed in ``blend_hip``.  Then Gaussian noise is added to
every centroid, ``n_missing`` of the star centroids are dropped at random, and ``n_false`` false
stars are added at uniformly random pixels (at least ``FALSE_STAR_CLEARANCE_PX`` from every
catalogue star image, so each centroid has one unambiguous truth) with V uniform in
``FALSE_STAR_V_RANGE``.  Centroid flux is 10^(-0.4 (V - 6)) (a V = 6 star gives 1), sorted
brightest first.

Frame sets (``n_false``, ``n_missing`` uniform integers in the ranges): main 0-3 / 0-2,
clean 0 / 0, stress 0-10 / 0-5.  Frame ``k`` of a set draws from child ``k`` of
``SeedSequence([seed, set index])`` (spawn key ``(k,)``), so it is the same whatever the number of frames.

Tracking priors: the truth attitude turned by a fixed angle (0.5, 1, 2, 5, 7 deg) about a
uniformly random axis, q_prior = q_IS (x) exp(angle axis) (body-axis error as in docs/design.md).

JSON Lines, one frame per line::

    {"id": "main-00000", "set": "main", "q_IS": [x, y, z, w], "ra_deg", "dec_deg", "roll_deg",
     "centroids": [[u, v, flux], ...], "hip": [HIP or -1 per centroid], "blend_hip":
     [[centroid index, HIP], ...], "n_false", "n_missing", "n_stars"}

and for tracking additionally ``"prior_q_IS"`` and ``"prior_error_deg"``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from startrack.base.units import DEG
from startrack.camera.model import Camera
from startrack.catalog.hipparcos import StarCatalog, load_star_catalog
from startrack.geometry.attitude_angles import radec_roll_from_quaternion

FOV_DEG = 16.0
WIDTH_PX = 1024
HEIGHT_PX = 1024
V_MAX = 6.0
CENTROID_SIGMA_PX = 0.1
CATALOG_EPOCH = 2000.0
#: Star images closer than this [px] are one centroid.
BLEND_RADIUS_PX = 2.0
#: False stars keep at least this distance [px] from every catalogue star image.
FALSE_STAR_CLEARANCE_PX = 5.0
#: Visual magnitudes [mag] of false stars: uniform over this range.
FALSE_STAR_V_RANGE = (2.0, 6.0)
#: Prior attitude errors [deg] of the tracking sweep.
TRACKING_PRIOR_ERRORS_DEG = (0.5, 1.0, 2.0, 5.0, 7.0)


@dataclass(frozen=True)
class FrameSet:
    """A set of frames: its name, index (seed stream) and the ranges of false and missing stars."""

    name: str
    index: int
    max_false: int
    max_missing: int


FRAME_SETS = {
    "main": FrameSet("main", 0, max_false=3, max_missing=2),
    "clean": FrameSet("clean", 1, max_false=0, max_missing=0),
    "stress": FrameSet("stress", 2, max_false=10, max_missing=5),
}
_TRACKING_STREAM = 3


def benchmark_camera() -> Camera:
    """The benchmark's camera: pinhole, 16 deg across 1024 x 1024 pixels."""
    return Camera.from_fov(FOV_DEG * DEG, WIDTH_PX, HEIGHT_PX)


def benchmark_stars(epoch: float = CATALOG_EPOCH) -> StarCatalog:
    """The stars a frame can contain: Hipparcos-2 with V <= 6.0 at ``epoch``."""
    return load_star_catalog(epoch).brighter_than(V_MAX)


def flux_from_magnitude(v_mag):
    """Centroid flux (a V = 6 star gives 1): 10^(-0.4 (V - 6))."""
    return 10.0 ** (-0.4 * (np.asarray(v_mag, dtype=float) - V_MAX))


def _blend(uv, flux, radius_px):
    """Merge images closer than ``radius_px``: (uv, flux, member lists brightest first)."""
    members = [[k] for k in range(len(uv))]
    pairs = cKDTree(uv).query_pairs(radius_px, output_type="ndarray") if len(uv) > 1 else np.empty((0, 2), int)
    if len(pairs):
        parent = np.arange(len(uv))

        def root(k):
            while parent[k] != k:
                k = parent[k]
            return k

        for i, j in pairs:
            parent[root(j)] = root(i)
        groups = {}
        for k in range(len(uv)):
            groups.setdefault(root(k), []).append(k)
        members = [sorted(group, key=lambda k: -flux[k]) for group in groups.values()]
    merged_flux = np.array([flux[group].sum() for group in members])
    merged_uv = np.array([flux[group] @ uv[group] / flux[group].sum() for group in members]).reshape(-1, 2)
    return merged_uv, merged_flux, members


def make_frame(frame_set: FrameSet, k: int, seed: int, stars: StarCatalog, camera: Camera) -> dict:
    """Frame ``k`` of ``frame_set`` (see the module docstring); deterministic in (seed, set, k)."""
    rng = np.random.default_rng(np.random.SeedSequence([seed, frame_set.index], spawn_key=(k,)))
    q_IS = Rotation.random(random_state=rng).as_quat()
    in_field = camera.stars_in_field(q_IS, stars.vectors)
    uv_true, _ = camera.project(q_IS, stars.vectors[in_field])
    star_flux = flux_from_magnitude(stars.v_mag[in_field])
    uv, flux, members = _blend(uv_true, star_flux, BLEND_RADIUS_PX)
    hip_of_star = stars.hip[in_field]
    uv = uv + rng.normal(scale=CENTROID_SIGMA_PX, size=uv.shape)
    hip = np.array([hip_of_star[group[0]] for group in members], dtype=np.int64)
    blends = [[hip_of_star[m] for m in group[1:]] for group in members]

    on_sensor = (
        (uv[:, 0] >= -0.5) & (uv[:, 0] <= camera.width - 0.5) & (uv[:, 1] >= -0.5) & (uv[:, 1] <= camera.height - 0.5)
    )
    keep = np.flatnonzero(on_sensor)
    n_missing = min(int(rng.integers(0, frame_set.max_missing + 1)), len(keep))
    keep = np.sort(rng.permutation(keep)[n_missing:])
    uv, flux, hip = uv[keep], flux[keep], hip[keep]
    blends = [blends[i] for i in keep]

    n_false = int(rng.integers(0, frame_set.max_false + 1))
    false_uv = np.empty((0, 2))
    tree = cKDTree(uv_true) if len(uv_true) else None
    while len(false_uv) < n_false:
        candidate = rng.uniform([-0.5, -0.5], [camera.width - 0.5, camera.height - 0.5])
        clear = tree is None or tree.query(candidate)[0] >= FALSE_STAR_CLEARANCE_PX
        clear = clear and all(np.hypot(*(candidate - f)) >= FALSE_STAR_CLEARANCE_PX for f in false_uv)
        if clear:
            false_uv = np.vstack([false_uv, candidate])
    false_flux = flux_from_magnitude(rng.uniform(*FALSE_STAR_V_RANGE, size=n_false))

    uv = np.vstack([uv, false_uv])
    flux = np.concatenate([flux, false_flux])
    hip = np.concatenate([hip, -np.ones(n_false, dtype=np.int64)])
    blends = blends + [[] for _ in range(n_false)]
    order = np.argsort(-flux, kind="stable")
    ra, dec, roll = radec_roll_from_quaternion(q_IS)
    return {
        "id": f"{frame_set.name}-{k:05d}",
        "set": frame_set.name,
        "q_IS": [float(x) for x in q_IS],
        "ra_deg": float(np.degrees(ra)),
        "dec_deg": float(np.degrees(dec)),
        "roll_deg": float(np.degrees(roll)),
        "centroids": [[float(u), float(v), float(f)] for (u, v), f in zip(uv[order], flux[order])],
        "hip": [int(h) for h in hip[order]],
        "blend_hip": [[int(i), int(h)] for i, j in enumerate(order) for h in blends[j]],
        "n_false": n_false,
        "n_missing": n_missing,
        "n_stars": int(len(keep)),
    }


def generate_frames(set_name: str, n_frames: int, seed: int = 0, stars: StarCatalog | None = None,
                    camera: Camera | None = None) -> list[dict]:
    """The first ``n_frames`` frames of the set ``set_name`` ("main", "clean" or "stress")."""
    stars = benchmark_stars() if stars is None else stars
    camera = benchmark_camera() if camera is None else camera
    frame_set = FRAME_SETS[set_name]
    return [make_frame(frame_set, k, seed, stars, camera) for k in range(n_frames)]


def tracking_frames(frames: list[dict], prior_errors_deg=TRACKING_PRIOR_ERRORS_DEG, seed: int = 0) -> list[dict]:
    """Copies of ``frames`` with a prior attitude off by each angle of ``prior_errors_deg``.

    The error rotation is body-axis: q_prior = q_IS (x) exp(angle axis), axis uniform on the sphere.
    """
    out = []
    for e, error_deg in enumerate(prior_errors_deg):
        rng = np.random.default_rng(np.random.SeedSequence([seed, _TRACKING_STREAM, e]))
        axes = rng.normal(size=(len(frames), 3))
        axes /= np.linalg.norm(axes, axis=1, keepdims=True)
        errors = Rotation.from_rotvec(axes * error_deg * DEG)
        for frame, error in zip(frames, errors):
            prior = (Rotation.from_quat(frame["q_IS"]) * error).as_quat()
            out.append(dict(frame, id=f"{frame['id']}-prior{error_deg:g}", prior_q_IS=[float(x) for x in prior],
                            prior_error_deg=float(error_deg)))
    return out


def write_jsonl(path, records) -> Path:
    """Write ``records`` (dicts) to ``path``, one JSON object per line.

    A file that already holds exactly these lines is left alone (its modification time tells the
    harness whether results computed from it are current).
    """
    path = Path(path)
    text = "".join(json.dumps(record) + "\n" for record in records)
    if not path.is_file() or path.read_text() != text:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return path


def read_jsonl(path) -> list[dict]:
    """The JSON objects of a JSON Lines file, in order."""
    with Path(path).open() as stream:
        return [json.loads(line) for line in stream if line.strip()]
