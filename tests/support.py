"""Helpers the test modules share: a command line called in process, the text of a PDF report."""

import pypdf


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
