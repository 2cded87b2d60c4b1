"""The report of a static study (:mod:`navsim.studies`): key results, parameters, our figures beside the
source document's, the explanation of every difference, and the study's figures."""

import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np

from navsim.studies import STUDIES
from navsim.typeset import figures
from navsim.typeset.document import Document, markup, number, scenario_name, table
from navsim.typeset.inputs import read_json
from navsim.typeset.sections import comparison_section, notes_section, scenario_section
from startrack import InputError


def study_report(study) -> bytes:
    """The PDF (bytes) of a static study's directory: key results, parameters, our figures beside the
    source document's, the explanation of every difference, and the study's figures."""
    summary = study.summary
    kind = summary["study"]
    module = STUDIES[kind]
    parameters = study.scenario["study"][kind]
    name = scenario_name(summary, study.scenario, study.directory)
    with tempfile.TemporaryDirectory(prefix="navsim-report-") as tmp, matplotlib.rc_context(figures.STYLE):
        doc = Document(Path(tmp), f"navsim study report: {name}", f"navsim study · {name}")
        doc.title(f"Static study report: {name}", study.scenario.get("description") or str(study.directory))
        doc.paragraph(markup(f"Study directory {study.directory}; kind {kind}; seed {summary.get('seed', 'n/a')}; "
                             f"wall time {number(summary.get('wall_seconds'), 1)} s."))
        doc.heading("Key results")
        doc.add(table(("Quantity", "Value", "Unit"), module.key_results(summary, parameters), ("left", "right", "left")))
        scenario_section(doc, study.scenario)
        comparison_section(doc, summary)
        notes_section(doc, summary)
        doc.heading("Figures")
        for fig, caption in module.figures(summary, study.arrays, parameters):
            doc.figure(fig, caption)
        return doc.compile()


@dataclass
class StudyData:
    """A static study: its summary, scenario (with the kind's parameters) and per-sample arrays."""

    directory: Path
    summary: dict
    scenario: dict
    arrays: dict


def load_study(directory: Path) -> StudyData:
    summary = read_json(directory / "summary.json")
    scenario = read_json(directory / "scenario.json") if (directory / "scenario.json").is_file() else {}
    kind = summary.get("study")
    if kind not in STUDIES:
        raise InputError(f"{directory / 'summary.json'}: 'study' must name a static study "
                         f"({', '.join(STUDIES)}), got {kind!r}.")
    parameters = scenario.get("study", {}).get(kind)
    if not isinstance(parameters, dict):
        raise InputError(f"{directory / 'scenario.json'}: missing, or without the study.{kind} parameters.")
    path = directory / "study.npz"
    if not zipfile.is_zipfile(path):
        raise InputError(f"{path}: not an .npz array file (not a zip archive).")
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {name: data[name] for name in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as error:
        raise InputError(f"{path}: cannot read it as an .npz array file ({error}).") from None
    return StudyData(directory, summary, scenario, arrays)
