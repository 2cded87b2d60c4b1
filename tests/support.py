"""Helpers the test modules share: a command line called in process, the text of a PDF report, the
deadline that turns a hung subprocess into a failure, a campaign's finished runs, a clock for time budgets."""

import re
import time

import pypdf

#: Seconds after which a subprocess or a wait counts as hung: only a hang fails at it, never a slow machine.
HANG_S = 1800.0


def run_cli(main, argv, capsys):
    """(exit status, stderr) of ``main(argv)``, an argparse exit counted as a status."""
    try:
        status = main([str(a) for a in argv])
    except SystemExit as exit_:
        status = exit_.code
    return status, capsys.readouterr().err


def pdf_text(path):
    """(all text of the PDF with whitespace runs collapsed so line breaks do not split phrases, page count)."""
    reader = pypdf.PdfReader(path)
    return " ".join(" ".join(page.extract_text() for page in reader.pages).split()), len(reader.pages)


def finished_runs(campaign_dir):
    """The run directories of a campaign that are in place (``runs/run_NNNNN``, not a ``.partial`` being
    written) and hold their summary."""
    runs = campaign_dir / "runs"
    if not runs.is_dir():
        return []
    return [p for p in runs.iterdir() if re.fullmatch(r"run_\d+", p.name) and (p / "summary.json").is_file()]


def wait_for(condition, what):
    """Poll ``condition()`` until it is true; fail only when it stays false for HANG_S (a hang)."""
    deadline = time.monotonic() + HANG_S
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError(f"hung: {what} did not happen within {HANG_S:.0f} s")
        time.sleep(0.002)


class SteppedClock:
    """A stand-in for ``time.perf_counter`` that advances ``step`` seconds per call: a time budget then ends
    after the same number of looks at the clock on any machine."""

    def __init__(self, step):
        self.step, self.now = step, 0.0

    def __call__(self):
        self.now += self.step
        return self.now
