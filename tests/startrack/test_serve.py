"""``startrack serve`` and the client inside ``startrack solve`` (startrack/serve_client.py): a one-shot
solve handed to a running solver answers exactly what the command answers in its own process."""

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from startrack import serve_client
from startrack.cli import main
from tests.support import HANG_S, wait_for

DATA = Path(__file__).resolve().parents[1] / "data" / "realsky"
IMAGE = DATA / "2019-07-29T204726_Alt60_Azi135_Try1.tiff"
STARTRACK = str(Path(sys.executable).parent / "startrack")


class Server:
    """A ``startrack serve`` subprocess on a socket of its own; its log lines collected from stderr."""

    def __init__(self):
        self.folder = Path(tempfile.mkdtemp(prefix="st", dir="/tmp"))  # AF_UNIX paths: at most 107 bytes
        self.socket = self.folder / "serve.sock"
        self.log = self.folder / "log.txt"
        with open(self.log, "w") as log:
            self.process = subprocess.Popen([STARTRACK, "serve", "--socket", str(self.socket)], stderr=log,
                                            stdout=subprocess.DEVNULL)
        wait_for(lambda: "listening" in self.log.read_text() or self.process.poll() is not None, "the server")
        assert self.process.poll() is None, self.log.read_text()

    def env(self, **extra):
        return {**os.environ, serve_client.SOCKET_ENV: str(self.socket), **extra}

    def solve(self, *argv, cwd=None, **env):
        return subprocess.run([STARTRACK, "solve", *map(str, argv)], capture_output=True, text=True, cwd=cwd,
                              env=self.env(**env), timeout=HANG_S)

    def lines(self):
        return self.log.read_text().splitlines()

    def stop(self):
        self.process.send_signal(signal.SIGTERM)
        self.process.wait(timeout=HANG_S)
        shutil.rmtree(self.folder, ignore_errors=True)


@pytest.fixture(scope="module")
def server():
    running = Server()
    yield running
    if running.process.poll() is None:
        running.stop()


def _records(text):
    records = [json.loads(line) for line in text.splitlines()]
    for record in records:
        record.pop("solve_ms", None)
    return records


def test_a_forwarded_solve_answers_what_the_command_answers_in_its_own_process(server, capsys):
    served = server.solve(IMAGE, "--json")
    assert served.returncode == 0, served.stderr
    assert any(IMAGE.name in line and "-> 0 (" in line for line in server.lines())
    assert main(["solve", str(IMAGE), "--json"]) == 0
    assert _records(served.stdout) == _records(capsys.readouterr().out)


def test_relative_paths_are_the_clients_and_errors_keep_their_line_and_status(server):
    served = server.solve(IMAGE.name, "--json", cwd=DATA)
    assert served.returncode == 0 and json.loads(served.stdout)["status"] == "ok"
    missing = server.solve("no_such_frame.tiff", cwd=DATA)
    assert missing.returncode == 2
    assert missing.stderr.strip().splitlines() == ["startrack: error: input file no_such_frame.tiff does not exist."]
    assert missing.stdout == ""


def test_outputs_are_written_where_the_client_says(server, tmp_path):
    served = server.solve(IMAGE, "--wcs", "out.wcs", cwd=tmp_path)
    assert served.returncode == 0, served.stderr
    assert (tmp_path / "out.wcs").is_file()


def test_other_code_a_stream_or_use_server_0_solve_in_the_clients_process(server, monkeypatch):
    monkeypatch.setenv(serve_client.SOCKET_ENV, str(server.socket))
    monkeypatch.setattr(serve_client, "code_version", lambda: "other code")
    assert serve_client.forward(["solve", str(IMAGE)]) is None
    # the server logs the refusal after sending it
    wait_for(lambda: server.lines()[-1].endswith("refused a client of other code"), "the refusal's log line")
    assert not serve_client.forwardable(["solve", "--batch", "-"])
    assert not serve_client.forwardable(["render", "-o", "x.png"])
    monkeypatch.setenv(serve_client.USE_ENV, "0")
    assert not serve_client.forwardable(["solve", str(IMAGE)])


def _raw(server, payload):
    connection = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    connection.connect(str(server.socket))
    connection.sendall(payload)
    connection.shutdown(socket.SHUT_WR)
    answer = b""
    while chunk := connection.recv(65536):
        answer += chunk
    connection.close()
    return answer


def test_bad_requests_are_refused_or_dropped_and_the_server_goes_on(server):
    other = json.dumps({"version": serve_client.code_version(), "argv": ["render", "-o", "/tmp/x.png"], "cwd": "/"})
    assert json.loads(_raw(server, other.encode() + b"\n")) == {"refused": "the server answers startrack solve only"}
    assert _raw(server, b"not json\n") == b""
    wait_for(lambda: server.lines()[-1].endswith("dropped a request: the request is not JSON"), "the drop's log line")
    assert _raw(server, b'{"argv": "solve"}\n') == b""
    assert server.solve(IMAGE).returncode == 0


def test_a_second_server_on_a_live_socket_or_on_a_file_is_refused(server, tmp_path):
    again = subprocess.run([STARTRACK, "serve", "--socket", str(server.socket)], capture_output=True, text=True,
                           timeout=HANG_S)
    assert again.returncode == 2
    assert again.stderr.strip() == f"startrack: error: a server already listens on {server.socket}"
    plain = tmp_path / "file"
    plain.write_text("mine")
    refused = subprocess.run([STARTRACK, "serve", "--socket", str(plain)], capture_output=True, text=True, timeout=HANG_S)
    assert refused.returncode == 2 and "is not a socket" in refused.stderr and plain.read_text() == "mine"


def test_sigterm_stops_the_server_and_removes_its_socket_then_solve_runs_alone():
    running = Server()
    running.process.send_signal(signal.SIGTERM)
    assert running.process.wait(timeout=HANG_S) == 0
    assert not running.socket.exists() and running.lines()[-1] == "startrack serve: stopped"
    alone = running.solve(IMAGE, "--json")
    assert alone.returncode == 0 and json.loads(alone.stdout)["status"] == "ok"
    shutil.rmtree(running.folder, ignore_errors=True)
