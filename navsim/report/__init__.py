"""PDF reports of a run directory, a static-study directory, a Monte Carlo campaign directory, an error
budget's directory or a replay's (``navsim replay``).

    >>> from navsim.report import write_report
    >>> write_report("reports/out/demo", "reports/out/demo.pdf")   # doctest: +SKIP

The kind of directory is detected from its contents (``campaign.json`` -> campaign; ``budget.json`` ->
error budget; ``summary.json`` + ``timeseries.npz`` -> run; ``summary.json`` + ``study.npz`` -> static
study), and the kind of run from its scenario (:mod:`navsim.kinds`: each kind typesets its own runs and
campaigns with :mod:`navsim.typeset`). Figures and sections whose quantities a run did not log
(vector-fidelity runs log no image-chain data) are left out and listed as absent.
"""

import json
from pathlib import Path

from navsim.kinds import of
from navsim.output import read_npz
from navsim.report.budget import budget_report
from navsim.report.covariance import covariance_report, sweep_report
from navsim.report.replay import replay_report
from navsim.report.study import load_study, study_report
from navsim.typeset.inputs import campaign_runs, directory_kind, load_campaign, load_run, read_json
from startrack import InputError

__all__ = ["write_report"]


def write_report(directory, pdf_path) -> Path:
    """Typeset the report of ``directory`` (run, study, campaign or budget) into ``pdf_path``; returns the PDF's path."""
    directory = Path(directory)
    pdf_path = Path(pdf_path)
    if pdf_path.suffix.lower() != ".pdf":
        raise InputError(f"{pdf_path}: the report file name must end in .pdf.")
    pdf = _typeset(directory, directory_kind(directory))
    try:
        pdf_path.parent.mkdir(parents=True, exist_ok=True)
        pdf_path.write_bytes(pdf)
    except OSError as error:
        raise InputError(f"{pdf_path}: cannot write the report ({error.strerror}).") from None
    return pdf_path


def _typeset(directory, output):
    """The PDF (bytes) of ``directory`` holding an output of kind ``output`` (:func:`directory_kind`)."""
    if output == "study":
        return study_report(load_study(directory))
    if output == "covariance":
        return covariance_report(read_json(directory / "summary.json"), read_npz(directory / "timeseries.npz"))
    if output == "sweep":
        return sweep_report(read_json(directory / "sweep.json"))
    if output == "replay":
        return replay_report(read_json(directory / "summary.json"), read_npz(directory / "timeseries.npz"))
    if output == "budget":
        series = directory / "timeseries.npz"
        return budget_report(read_json(directory / "budget.json"), read_npz(series) if series.is_file() else None)
    if output == "campaign":
        campaign = read_json(directory / "campaign.json")
        finished, failed = campaign_runs(directory)
        kind = _kind(campaign.get("scenario_data"), directory / "campaign.json")
        return kind.campaign_report(load_campaign(directory, campaign, kind, finished, failed))
    kind = _kind(read_json(directory / "scenario.json"), directory / "scenario.json")
    return kind.run_report(load_run(directory, kind))


def _kind(scenario, path):
    """The run kind of the validated scenario a run or campaign directory stores (``path``)."""
    if not isinstance(scenario, dict) or "name" not in scenario:
        raise InputError(f"{path}: holds no validated scenario ({json.dumps(scenario)[:60]}); it was not written by "
                         "navsim run or navsim montecarlo.")
    return of(scenario)
