"""``startrack catalog`` and ``startrack address``: JSON contract, text output, bad input."""

import json
import os
import subprocess
import sys

import pytest

from startrack.cli import main
from tests.support import HANG_S

CATALOG_KEYS = {
    "candidates", "excluded", "guide_stars", "base_points", "s_max_deg", "rho_sub_deg", "pairs",
    "subcatalog_stars", "subcatalog_pairs", "memory_bytes", "build_seconds", "from_cache",
}  # fmt: skip


def run_json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_catalog_json_contract_and_cache(capsys):
    argv = ["catalog", "--mag", "6.0", "--fov-deg", "16", "--nd", "53", "--json", "--rebuild"]
    first = run_json(capsys, argv)
    assert CATALOG_KEYS <= set(first)
    assert first["base_points"] == 3100
    assert set(first["excluded"]) == {"magnitude", "multiple", "variable"}
    assert set(first["subcatalog_stars"]) == set(first["subcatalog_pairs"]) == {"min", "max", "mean"}
    assert first["memory_bytes"]["total"] == sum(v for k, v in first["memory_bytes"].items() if k != "total")
    assert first["from_cache"] is False
    second = run_json(capsys, argv[:-1])
    assert second["from_cache"] is True
    assert {k: second[k] for k in ("guide_stars", "pairs")} == {k: first[k] for k in ("guide_stars", "pairs")}


def test_catalog_switches_change_the_candidates(capsys):
    loose = run_json(capsys, ["catalog", "--keep-multiple", "--keep-variable", "--json"])
    assert loose["excluded"]["multiple"] == loose["excluded"]["variable"] == 0
    strict = run_json(capsys, ["catalog", "--json"])
    assert loose["candidates"] == strict["candidates"] + strict["excluded"]["multiple"] + strict["excluded"]["variable"]


def test_catalog_text_table(capsys):
    assert main(["catalog"]) == 0
    out = capsys.readouterr().out
    for text in ("candidates", "guide stars", "pattern pairs", "k-vector table", "SKYMAP 2000", "4908", "2717"):
        assert text in out


def test_catalog_plot_writes_the_figures(capsys, tmp_path):
    stats = run_json(capsys, ["catalog", "--json", "--plot", str(tmp_path / "figs")])
    names = sorted(os.path.basename(p) for p in stats["figures"])
    assert names == ["catalog_homogenisation.png", "catalog_subcatalogs.png"]
    for path in stats["figures"]:
        with open(path, "rb") as handle:
            assert handle.read(8) == b"\x89PNG\r\n\x1a\n"


def test_address_json_table_2(capsys):
    out = run_json(capsys, ["address", "--ra-deg", "62.27", "--dec-deg", "38.67", "--nd", "53", "--json"])
    assert (out["l_d"], out["l_ra"]) == (38, 13)
    assert [n["direction"] for n in out["neighbours"]] == ["east", "west", "north", "south"]
    assert out["rho_sub_deg"] == pytest.approx(12.0)
    assert {n["l_d"] for n in out["neighbours"][2:]} == {41, 34}  # +-12 deg in Dec: rings 38 +- 12*53/180


def test_address_text(capsys):
    assert main(["address", "--ra-deg", "359.5", "--dec-deg", "-89"]) == 0
    out = capsys.readouterr().out
    assert "predicted" in out and "north" in out and "l_ra" in out


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["address", "--ra-deg", "10", "--dec-deg", "95"], "--dec-deg"),
        (["address", "--ra-deg", "nan", "--dec-deg", "5"], "--ra-deg"),
        (["address", "--ra-deg", "10", "--dec-deg", "5", "--nd", "2"], "--nd"),
        (["catalog", "--fov-deg", "nan"], "--fov-deg"),
        (["catalog", "--mag", "40"], "--mag"),
        (["catalog", "--theta-min-deg", "9"], "--theta-min-deg"),
        (["catalog", "--sigma-arcsec", "-1"], "--sigma-arcsec"),
    ],
)
def test_bad_input_one_line_exit_2(capsys, argv, fragment):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("startrack: error:") and fragment in err and "\n" not in err


def test_plot_into_a_file_is_rejected(capsys, tmp_path):
    target = tmp_path / "file.png"
    target.write_text("x")
    assert main(["catalog", "--plot", str(target)]) == 2
    assert "--plot" in capsys.readouterr().err


def test_unparsable_numbers_exit_2_without_traceback():
    for argv in (["address", "--ra-deg", "abc", "--dec-deg", "1"], ["address", "--ra-deg", "1", "--dec-deg", "91"],
                 ["catalog", "--nd", "x"]):  # fmt: skip
        result = subprocess.run([sys.executable, "-m", "startrack.cli", *argv], capture_output=True, text=True,
                                timeout=HANG_S)  # fmt: skip
        assert result.returncode == 2
        assert "Traceback" not in result.stderr and "error" in result.stderr
