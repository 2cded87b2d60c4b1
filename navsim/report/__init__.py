"""PDF reports of a run directory or a Monte Carlo campaign directory.

    >>> from navsim.report import write_report
    >>> write_report("reports/out/demo", "reports/out/demo.pdf")   # doctest: +SKIP

The kind of directory is detected from its contents (``campaign.json`` -> campaign;
``summary.json`` + ``timeseries.npz`` -> run). Figures and sections whose quantities a run did
not log (vector-fidelity runs log no image-chain data) are left out and listed as absent.
"""

from pathlib import Path

from navsim.report import document
from navsim.report.inputs import directory_kind, load_campaign, load_run
from startrack.errors import InputError

__all__ = ["write_report"]


def write_report(directory, pdf_path) -> Path:
    """Typeset the report of ``directory`` (run or campaign) into ``pdf_path``; returns the PDF's path."""
    directory = Path(directory)
    pdf_path = Path(pdf_path)
    if pdf_path.suffix.lower() != ".pdf":
        raise InputError(f"{pdf_path}: the report file name must end in .pdf.")
    if directory_kind(directory) == "campaign":
        pdf = document.campaign_report(load_campaign(directory))
    else:
        pdf = document.run_report(load_run(directory))
    try:
        pdf_path.parent.mkdir(parents=True, exist_ok=True)
        pdf_path.write_bytes(pdf)
    except OSError as error:
        raise InputError(f"{pdf_path}: cannot write the report ({error.strerror}).") from None
    return pdf_path
