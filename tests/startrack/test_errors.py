"""The command-line runner: every way a command ends is one line and its exit status."""

import pytest

from startrack.base.errors import ArgumentParser, InputError, interrupted, run_command


def _command(failure):
    def build_parser():
        parser = ArgumentParser(prog="tool")
        parser.set_defaults(func=lambda args: failure())
        return parser
    return build_parser


def _kernel_interrupted():
    """What numba raises when Ctrl-C lands inside a compiled kernel."""
    try:
        raise KeyboardInterrupt
    except KeyboardInterrupt as interrupt:
        raise SystemError("CPUDispatcher(<function run_stars>) returned a result with an exception set") from interrupt


def _raise(error):
    def fail():
        raise error
    return fail


@pytest.mark.parametrize(("failure", "status", "line"), [
    (_raise(InputError("scenario.toml: gyro.rate_hz: must be > 0, got -1")), 2,
     "tool: error: scenario.toml: gyro.rate_hz: must be > 0, got -1"),
    (_raise(KeyboardInterrupt()), 130, "tool: interrupted"),
    (_kernel_interrupted, 130, "tool: interrupted"),
    (_raise(OSError(28, "No space left on device", "out/summary.json")), 1,
     "tool: error: out/summary.json: No space left on device"),
])
def test_each_ending_is_one_line(capsys, failure, status, line):
    assert run_command("tool", _command(failure), []) == status
    assert capsys.readouterr().err.strip().splitlines() == [line]


def test_a_defect_of_ours_is_an_internal_error_without_traceback(capsys, monkeypatch):
    monkeypatch.delenv("STARTRACK_DEBUG", raising=False)
    assert run_command("tool", _command(_raise(RuntimeError("index out of range"))), []) == 70
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith("tool: internal error: RuntimeError: index out of range")


def test_an_interrupt_is_found_anywhere_in_the_chain_of_causes():
    try:
        try:
            _kernel_interrupted()
        except SystemError as inner:
            raise RuntimeError("while writing the run") from inner
    except RuntimeError as outer:
        assert interrupted(outer)
    assert not interrupted(RuntimeError("no interrupt"))
