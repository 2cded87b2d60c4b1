"""PDF reports of a run directory, a static-study directory or a Monte Carlo campaign directory.

    >>> from navsim.report import write_report
    >>> write_report("reports/out/demo", "reports/out/demo.pdf")   # doctest: +SKIP

The kind of directory is detected from its contents (``campaign.json`` -> campaign;
``summary.json`` + ``timeseries.npz`` -> run; ``summary.json`` + ``study.npz`` -> static study), and
the kind of run from its summary (attitude: :mod:`navsim.report.document`; navigation, the INS:
:mod:`navsim.report.navigation`). Figures and sections whose quantities a run did
not log (vector-fidelity runs log no image-chain data) are left out and listed as absent.
"""

from pathlib import Path

from navsim.report import document, navigation
from navsim.report.inputs import directory_kind, load_campaign, load_run, load_study
from startrack.errors import InputError

__all__ = ["write_report"]


def write_report(directory, pdf_path) -> Path:
    """Typeset the report of ``directory`` (run, study or campaign) into ``pdf_path``; returns the PDF's path."""
    directory = Path(directory)
    pdf_path = Path(pdf_path)
    if pdf_path.suffix.lower() != ".pdf":
        raise InputError(f"{pdf_path}: the report file name must end in .pdf.")
    kind = directory_kind(directory)
    if kind == "campaign":
        campaign = load_campaign(directory)
        report = navigation if campaign.runs[0].summary.kind == "navigation" else document
        pdf = report.campaign_report(campaign)
    elif kind == "study":
        pdf = document.study_report(load_study(directory))
    else:
        run = load_run(directory)
        pdf = (navigation if run.summary.kind == "navigation" else document).run_report(run)
    try:
        pdf_path.parent.mkdir(parents=True, exist_ok=True)
        pdf_path.write_bytes(pdf)
    except OSError as error:
        raise InputError(f"{pdf_path}: cannot write the report ({error.strerror}).") from None
    return pdf_path
