"""The bad-input corpus of the startrack command line: every numeric option of every command with
values it must refuse, and broken input files. Each case ends with one line that names the culprit,
a non-zero exit status, no traceback, and no output file."""

import math

import numpy as np
import pytest
from PIL import Image

from startrack import cli
from tests.support import run_cli

#: A valid call of each command ({tmp}: the test's directory) and its numeric options.
COMMANDS = {
    "catalog": (["catalog", "--mag", "4.5"],
                ["--mag", "--fov-deg", "--nd", "--sigma-arcsec", "--max-delta-deg", "--theta-min-deg", "--epoch",
                 "--plot-ra-deg", "--plot-dec-deg"]),
    "address": (["address", "--ra-deg", "10", "--dec-deg", "20"], ["--ra-deg", "--dec-deg", "--nd", "--fov-deg",
                                                                   "--max-delta-deg"]),
    "render": (["render", "--ra-deg", "10", "--dec-deg", "20", "--width", "64", "--height", "64", "-o", "{tmp}/r.png"],
               ["--ra-deg", "--dec-deg", "--roll-deg", "--fov-deg", "--width", "--height", "--mag-limit",
                "--exposure-ms", "--rate-deg-s", "--epoch", "--seed"]),
    "render 8-bit": (["render", "--ra-deg", "10", "--dec-deg", "20", "--width", "64", "--height", "64", "-o",
                      "{tmp}/r.png", "--bits", "8"], ["--black-dn", "--white-dn"]),
    "detect": (["detect", "{tmp}/frame.png"], ["--a", "--background-dn", "--sigma-n-dn", "--mesh-px", "--min-pixels",
                                               "--saturation-dn", "--psf-sigma-px", "--gain-e-per-dn"]),
    "detect --smear-px": (["detect", "{tmp}/frame.png", "--psf-sigma-px", "0.8", "--smear-px", "3,0"],
                          ["--false-alarms", "--smear-px", "--psf-sigma-px", "--background-dn", "--sigma-n-dn",
                           "--mesh-px", "--saturation-dn", "--gain-e-per-dn"]),
    "solve": (["solve", "{tmp}/frame.png"], ["--fov-deg", "--width", "--height", "--boresight-error-deg", "--mag",
                                             "--epoch", "--centroid-sigma-px", "--time-budget-s", "--max-false-match",
                                             "--a", "--background-dn", "--sigma-n-dn", "--mesh-px", "--min-pixels",
                                             "--saturation-dn"]),
}
BAD_NUMBERS = {"NaN": "nan", "infinite": "inf", "huge": "1e30", "negative huge": "-1e30", "a word": "abc"}
#: Options for which a negative or huge value is a legitimate input (angles wrap).
WRAPPING = {"--ra-deg", "--roll-deg", "--plot-ra-deg"}


def numeric_cases():
    cases = []
    for command, (base, options) in COMMANDS.items():
        for option in options:
            for label, value in BAD_NUMBERS.items():
                if option in WRAPPING and label in ("negative huge",):
                    continue
                cases.append((f"{command} {option} {label}", command, option, value))
    return cases


NUMERIC_CASES = numeric_cases()


def _inputs(tmp):
    """Input files: a rendered frame and broken ones."""
    from startrack.commands import render as _  # noqa: F401  (the renderer is what makes frame.png)

    assert cli.main(["render", "--ra-deg", "195", "--dec-deg", "0", "--fov-deg", "20", "--width", "256",
                     "--height", "256", "-o", str(tmp / "frame.png")]) == 0
    (tmp / "corrupt.png").write_bytes(b"\x89PNG\r\n\x1a\n garbage")
    (tmp / "empty.png").write_bytes(b"")
    (tmp / "text.tiff").write_text("not an image")
    np.save(tmp / "nan.npy", np.full((64, 64), np.nan))
    np.save(tmp / "flat.npy", np.zeros((64, 64)))
    np.save(tmp / "cube.npy", np.zeros((4, 4, 4)))
    Image.new("L", (1, 1)).save(tmp / "tiny.png")
    (tmp / "dir.png").mkdir()
    (tmp / "bad.csv").write_text("u,v\n1,nan\n")
    (tmp / "words.csv").write_text("u,v\na,b\n")
    (tmp / "empty.jsonl").write_text("\n\n")
    (tmp / "a_file").write_text("x")


def assert_one_clear_line(status, err, culprit):
    assert status not in (0, None), err
    assert "Traceback" not in err and "internal error" not in err, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("startrack"), err
    assert culprit in lines[0], (culprit, err)


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("corpus")
    _inputs(tmp)
    return tmp


@pytest.mark.parametrize("case_id, command, option, value", NUMERIC_CASES, ids=[c[0] for c in NUMERIC_CASES])
def test_every_numeric_option_refuses_a_bad_value(inputs, tmp_path, capsys, case_id, command, option, value):
    base, _ = COMMANDS[command]
    argv = [a.replace("{tmp}", str(tmp_path)) if a.startswith("{tmp}/r") else a.replace("{tmp}", str(inputs))
            for a in base]
    status, err = run_cli(cli.main, [*argv, option, value], capsys)
    assert_one_clear_line(status, err, option)
    assert not (tmp_path / "r.png").exists()


FILE_CASES = [
    ("detect: missing file", ["detect", "{in}/nope.png"], "nope.png"),
    ("detect: a directory", ["detect", "{in}/dir.png"], "dir.png"),
    ("detect: corrupt PNG", ["detect", "{in}/corrupt.png"], "corrupt.png"),
    ("detect: empty file", ["detect", "{in}/empty.png"], "empty.png"),
    ("detect: text as TIFF", ["detect", "{in}/text.tiff"], "text.tiff"),
    ("detect: NaN pixels", ["detect", "{in}/nan.npy"], "nan.npy"),
    ("detect: a cube", ["detect", "{in}/cube.npy"], "cube.npy"),
    ("detect: unknown suffix", ["detect", "{in}/a_file"], "a_file"),
    ("detect: unknown centroider", ["detect", "{in}/frame.png", "--centroider", "magic"], "--centroider"),
    ("detect: --smear-px without --psf-sigma-px", ["detect", "{in}/frame.png", "--smear-px", "3,0"], "--psf-sigma-px"),
    ("detect: --false-alarms without --smear-px", ["detect", "{in}/frame.png", "--false-alarms", "1"], "--false-alarms"),
    ("detect: --smear-px one number", ["detect", "{in}/frame.png", "--psf-sigma-px", "0.8", "--smear-px", "3"],
     "--smear-px"),
    ("detect: --smear-px too long", ["detect", "{in}/frame.png", "--psf-sigma-px", "0.8", "--smear-px", "300,0"],
     "--smear-px"),
    *[(f"detect: --smear-px with {extra[0]}", ["detect", "{in}/frame.png", "--psf-sigma-px", "0.8", "--smear-px", "3,0",
                                               *extra], extra[0])
      for extra in (("--a", "4"), ("--centroider", "grey"), ("--min-pixels", "2"), ("--keep-single-pixels",),
                    ("--keep-extended",))],
    ("solve: missing file", ["solve", "{in}/nope.png"], "nope.png"),
    ("solve: a directory", ["solve", "{in}/dir.png"], "dir.png"),
    ("solve: corrupt PNG", ["solve", "{in}/corrupt.png"], "corrupt.png"),
    ("solve: words as centroids", ["solve", "{in}/words.csv", "--fov-deg", "10", "--width", "512", "--height", "512"],
     "words.csv"),
    ("solve: empty batch", ["solve", "--batch", "{in}/empty.jsonl"], "empty.jsonl"),
    ("solve: missing batch", ["solve", "--batch", "{in}/nope.jsonl"], "nope.jsonl"),
    ("solve: missing camera file", ["solve", "{in}/frame.png", "--camera", "{in}/nope.toml"], "nope.toml"),
    ("solve: camera file is not TOML", ["solve", "{in}/frame.png", "--camera", "{in}/a_file"], "a_file"),
    ("solve: --fov-range-deg reversed", ["solve", "{in}/frame.png", "--fov-range-deg", "20,10"], "--fov-range-deg"),
    ("solve: --fov-range-deg words", ["solve", "{in}/frame.png", "--fov-range-deg", "a,b"], "--fov-range-deg"),
    ("solve: --boresight-deg one value", ["solve", "{in}/frame.png", "--boresight-deg", "10"], "--boresight-deg"),
    ("solve: --boresight-deg Dec 100", ["solve", "{in}/frame.png", "--boresight-deg", "10,100"], "--boresight-deg"),
    ("solve: --write-camera under a file", ["solve", "{in}/frame.png", "--write-camera", "{in}/a_file/c.toml"], "a_file"),
    ("solve: image size not --width", ["solve", "{in}/frame.png", "--width", "512"], "--width"),
    ("render: -o under a file", ["render", "--ra-deg", "1", "--dec-deg", "2", "-o", "{in}/a_file/r.png"], "a_file"),
    ("render: -o not an image", ["render", "--ra-deg", "1", "--dec-deg", "2", "-o", "{in}/r.txt"], "r.txt"),
    ("render: -o a directory", ["render", "--ra-deg", "1", "--dec-deg", "2", "-o", "{in}/dir.png"], "dir.png"),
    ("catalog: --plot under a file", ["catalog", "--mag", "4.5", "--plot", "{in}/a_file/p"], "a_file"),
    ("catalog: --plot a file", ["catalog", "--mag", "4.5", "--plot", "{in}/a_file"], "a_file"),
    ("address: no --dec-deg", ["address", "--ra-deg", "10"], "--dec-deg"),
    ("no command", [], "COMMAND"),
    ("unknown command", ["fly"], "fly"),
]


@pytest.mark.parametrize("case_id, argv, culprit", FILE_CASES, ids=[c[0] for c in FILE_CASES])
def test_broken_inputs_and_outputs_are_named(inputs, capsys, case_id, argv, culprit):
    status, err = run_cli(cli.main, [a.replace("{in}", str(inputs)) for a in argv], capsys)
    assert_one_clear_line(status, err, culprit)


def test_a_flat_frame_is_a_status_not_a_crash(inputs, capsys):
    """A frame with nothing above the threshold: the frame's status says so (exit 1), one line."""
    status, err = run_cli(cli.main, ["solve", inputs / "flat.npy"], capsys)
    assert status == 1 and "Traceback" not in err


def test_a_nan_centroid_is_the_frames_error(inputs, capsys):
    """A NaN centroid fails that frame: one status line naming the NaN on stdout, exit 1, no traceback."""
    status = cli.main(["solve", str(inputs / "bad.csv"), "--fov-deg", "10", "--width", "512", "--height", "512"])
    captured = capsys.readouterr()
    assert status == 1 and "Traceback" not in captured.err
    assert captured.out.count("\n") == 1 and "error" in captured.out and "NaN" in captured.out


def test_a_batch_line_of_bad_bytes_loses_only_that_frame(tmp_path, capsys):
    batch = tmp_path / "b.jsonl"
    batch.write_bytes(b'{"id": "a", "centroids": [[1, 2, 3]]}\n\xff\xfe bad\n{"id": "c", "centroids": []}\n')
    status = cli.main(["solve", "--batch", str(batch), "--fov-deg", "10", "--width", "512", "--height", "512"])
    out = capsys.readouterr().out.splitlines()
    assert status == 1 and len(out) == 3
    assert out[0].startswith("a:") and "line 2" in out[1] and out[2].startswith("c:")


def test_the_corpus_covers_every_numeric_option():
    assert len(NUMERIC_CASES) + len(FILE_CASES) >= 200
    assert math.isnan(float(BAD_NUMBERS["NaN"]))
