"""Calling a command line in process, as the bad-input corpora of both packages do."""


def run_cli(main, argv, capsys):
    """(exit status, stderr) of ``main(argv)``, an argparse exit counted as a status."""
    try:
        status = main([str(a) for a in argv])
    except SystemExit as exit_:
        status = exit_.code
    return status, capsys.readouterr().err
