"""Typeset the report: Typst source (text, tables, SVG figures) compiled to PDF by the ``typst``
package (the Typst compiler with its bundled fonts; no network, no system fonts).

Every string that comes from the data (scenario text, keys, error messages, numbers) enters the
Typst source either escaped for markup (:func:`markup`) or as a string literal (:func:`literal`),
so nothing in a run directory can change the document's structure. Key numbers are written as
plain text ("cross-boresight RMS 1.99 arcsec") so they can be extracted from the PDF.
"""

import math
from pathlib import Path

import typst

from navsim.typeset import figures

PREAMBLE = """\
#set document(title: {title}, author: "navsim", date: none)
#set page(paper: "a4", margin: (x: 2cm, y: 2.2cm), numbering: "1 / 1",
  header: align(right, text(size: 8pt, fill: luma(90), {header})))
#set text(size: 10pt, lang: "en")
#set par(justify: true)
#set heading(numbering: "1.")
#show heading.where(level: 1): set block(above: 1.4em, below: 0.8em)
#show table: set text(size: 8pt)
#show figure.caption: set text(size: 9pt)
#set table(stroke: (x, y) => if y == 0 {{ (bottom: 0.7pt) }} else {{ (bottom: 0.2pt + luma(200)) }},
  inset: (x: 4pt, y: 3pt))
"""


def literal(value) -> str:
    """A Typst string literal holding ``value`` verbatim."""
    text = str(value).replace("\\", "\\\\").replace('"', '\\"')
    text = text.replace("\r", " ").replace("\n", " ").replace("\t", " ")
    return '"' + text + '"'


def markup(value) -> str:
    """``value`` as Typst markup that shows it verbatim (ASCII punctuation backslash-escaped)."""
    out = []
    for ch in " ".join(str(value).split()):
        out.append("\\" + ch if ch.isascii() and not ch.isalnum() and ch != " " else ch)
    return "".join(out)


def number(x, digits=2, scale=1.0) -> str:
    """Fixed-point text of ``scale * x`` (``digits`` decimals); 'n/a' for anything not a finite number."""
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
        return "n/a"
    return f"{scale * x:.{digits}f}"


def xyz(values, digits=2) -> str:
    """'x a, y b, z c' for three per-axis values."""
    return ", ".join(f"{axis} {number(None if v is None else float(v), digits)}" for axis, v in zip("xyz", values))


def general(x) -> str:
    """A JSON value as table text: numbers to 6 significant digits, lists in brackets, booleans, text."""
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, int):
        return str(x)
    if isinstance(x, float):
        return f"{x:.6g}"
    if isinstance(x, list):
        return "[" + ", ".join(general(v) for v in x) + "]"
    return str(x)


def flatten(tree, prefix=""):
    """(dotted key, value) pairs of the scalar and list leaves of nested dictionaries, nulls left out."""
    rows = []
    for key in sorted(tree) if isinstance(tree, dict) else []:
        value = tree[key]
        path = f"{prefix}{key}"
        if isinstance(value, dict):
            rows.extend(flatten(value, path + "."))
        elif isinstance(value, list) and any(isinstance(v, (dict, list)) for v in value):
            continue
        elif value is not None:
            rows.append((path, value))
    return rows


def table(header, rows, align=None) -> str:
    """A Typst table with a bold header row; every cell a string literal."""
    columns = len(header)
    align = align or ("left",) + ("right",) * (columns - 1)
    cells = ", ".join(f"[*{markup(h)}*]" for h in header)
    body = ",\n  ".join(", ".join(literal(c) for c in row) for row in rows)
    return (f"#table(columns: {columns}, align: ({', '.join(align)},),\n"
            f"  table.header({cells}),\n  {body}\n)\n")


class Document:
    """Typst source under construction plus the figure files it refers to (in one directory)."""

    def __init__(self, workdir: Path, title: str, header: str):
        self.workdir = workdir
        self.parts = [PREAMBLE.format(title=literal(title), header=literal(header))]
        self.lead = []  # paragraphs kept on the page of the figure that follows them
        self.count = 0

    def add(self, source: str):
        self.parts.extend(self.lead)
        self.lead = []
        self.parts.append(source)

    def title(self, title, subtitle):
        self.add(f"#align(center, text(size: 17pt, weight: \"bold\", {literal(title)}))\n"
                 f"#align(center, text(size: 10pt, fill: luma(60), {literal(subtitle)}))\n#v(1em)\n")

    def heading(self, text):
        self.add(f"\n= {markup(text)}\n")

    def paragraph(self, *sentences):
        """Sentences are markup already (build them with :func:`markup` and :func:`number`)."""
        self.lead.append(" ".join(s for s in sentences if s) + "\n\n")

    def figure(self, fig, caption):
        """Save ``fig`` as SVG beside the source and place it with the paragraphs just before it, on one page;
        a None figure adds nothing."""
        if fig is None:
            return
        self.count += 1
        name = f"figure_{self.count:02d}.svg"
        figures.save(fig, self.workdir / name)
        lead, self.lead = "".join(self.lead), []
        self.add(f"#block(breakable: false, width: 100%)[\n{lead}"
                 f"#figure(image({literal(name)}, width: 100%), caption: [{markup(caption)}])\n]\n")

    def source(self) -> str:
        return "".join(self.parts + self.lead)

    def compile(self) -> bytes:
        path = self.workdir / "report.typ"
        path.write_text(self.source(), encoding="utf-8")
        return typst.compile(str(path), root=str(self.workdir), ignore_system_fonts=True)


def scenario_name(summary, scenario, directory):
    for name in ((summary or {}).get("scenario"), (scenario or {}).get("name")):
        if isinstance(name, str) and name:
            return name
    return directory.name


def short(text, limit=90):
    return text if len(text) <= limit else text[: limit - 3] + "..."
