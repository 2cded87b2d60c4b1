"""``startrack serve``: a long-lived ``startrack solve`` for camera pipelines and observatory scripts.

It listens on a Unix socket (``--socket``, default :func:`startrack.serve_client.socket_path`) in a
folder only its user can enter, and answers only that user's connections (SO_PEERCRED).  Each
connection carries one ``startrack solve`` command line and the client's working directory
(:mod:`startrack.serve_client`'s JSON protocol); it is run here exactly as the command would run, its
printed lines sent back as they are printed, its exit status last.  The solvers are built once per set
of solver options (camera file, field of view, search, thresholds) and kept, so a request costs its
frames' reading, detection and solve.  Requests are answered one at a time.  Ctrl-C or SIGTERM stops the
server and removes the socket.

A plain ``startrack solve`` finds the server by itself (same socket path, same code) and hands it the
work; ``STARTRACK_USE_SERVER=0`` solves in the client's process instead.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import signal
import socket
import stat
import struct
import sys
import time
from pathlib import Path

from startrack.base.errors import InputError, run_command
from startrack.serve_client import code_version, socket_path

#: Largest request line [bytes] (a command line and a folder name).
_MAX_REQUEST_BYTES = 1 << 20
#: Options of ``startrack solve`` that define its solver (a request with the same values reuses it).
_SOLVER_OPTIONS = ("fov_deg", "refit", "fov_hint_deg", "fov_range_deg", "centroid_sigma_px", "epoch", "hdu",
                  "time_budget_s", "boresight_error_deg", "max_false_match", "mag")


def register(subparsers):
    parser = subparsers.add_parser(
        "serve", help="keep a solver running: `startrack solve` commands are handed to it (no start-up per call)",
        description="Answer `startrack solve` command lines sent over a Unix socket by the same user: the "
                    "solvers, catalogs and compiled kernels stay loaded, so each call costs its detection and "
                    "solve. A plain `startrack solve` uses a running server by itself (STARTRACK_USE_SERVER=0: "
                    "never).")
    parser.add_argument("--socket", metavar="PATH",
                        help=f"the socket to listen on (${'{'}STARTRACK_SERVE_SOCKET{'}'}, else {socket_path()})")
    parser.set_defaults(func=run)


class _ClientGone(Exception):
    """The client closed its connection before the answer's end."""


class _Messages(io.TextIOBase):
    """A text stream whose writes go to the client as JSON lines ``{key: text}``."""

    def __init__(self, connection, key):
        self._connection, self._key = connection, key

    def writable(self):
        return True

    def write(self, text):
        if text:
            _send(self._connection, {self._key: text})
        return len(text)


def _send(connection, message):
    try:
        connection.sendall(json.dumps(message).encode() + b"\n")
    except OSError as error:
        raise _ClientGone(str(error)) from None


class _SolverCache:
    """The frame solver of a ``solve`` command's options, built on first use and kept."""

    def __init__(self):
        self._solvers = {}

    @staticmethod
    def key(args):
        camera = None
        if args.camera is not None:
            path = Path(args.camera).resolve()
            stat = path.stat() if path.is_file() else None
            camera = (str(path), stat and stat.st_size, stat and stat.st_mtime_ns)
        return (camera, args.write_camera is not None, *(getattr(args, name) for name in _SOLVER_OPTIONS))

    def __call__(self, args):
        from startrack.commands.solve import frame_solver

        key = self.key(args)
        if key not in self._solvers:
            self._solvers[key] = frame_solver(args)
        return self._solvers[key]


def _read_request(connection):
    """The request's dict (version, argv, cwd), or InputError naming what is wrong with it."""
    data = b""
    while not data.endswith(b"\n"):
        chunk = connection.recv(65536)
        if not chunk or len(data) + len(chunk) > _MAX_REQUEST_BYTES:
            raise InputError("the request is not one JSON line of at most 1 MB")
        data += chunk
    try:
        request = json.loads(data)
    except ValueError:
        raise InputError("the request is not JSON") from None
    argv = request.get("argv") if isinstance(request, dict) else None
    if not (isinstance(argv, list) and all(isinstance(a, str) for a in argv) and isinstance(request.get("cwd"), str)
            and isinstance(request.get("version"), str)):
        raise InputError("the request needs version, argv (a list of strings) and cwd")
    return request


def _peer_uid(connection):
    return struct.unpack("3i", connection.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, struct.calcsize("3i")))[1]


def _answer(connection, request, solvers):
    """Run the request's ``startrack solve`` here; its exit status."""
    from startrack.commands import build_parser
    from startrack.commands.solve import run as solve

    try:
        os.chdir(request["cwd"])
    except OSError as error:
        _send(connection, {"stderr": f"startrack: error: the working directory {request['cwd']}: {error.strerror}\n"})
        return 2
    with contextlib.redirect_stdout(_Messages(connection, "stdout")),\
            contextlib.redirect_stderr(_Messages(connection, "stderr")):
        return run_command("startrack", build_parser, request["argv"], call=lambda args: solve(args, solvers))


def _serve(connection, solvers, version, home):
    """Answer one connection; the line the server prints about it."""
    start = time.perf_counter()
    try:
        if _peer_uid(connection) != os.getuid():
            _send(connection, {"refused": "another user's connection"})
            return "refused another user's connection"
        request = _read_request(connection)
        if request["version"] != version:
            _send(connection, {"refused": f"the server runs other code ({version})"})
            return "refused a client of other code"
        if request["argv"][:1] != ["solve"]:
            _send(connection, {"refused": "the server answers startrack solve only"})
            return f"refused {' '.join(request['argv'][:1]) or 'an empty command'}"
        status = _answer(connection, request, solvers)
        _send(connection, {"status": status})
    except (InputError, _ClientGone, OSError) as error:
        return f"dropped a request: {error}"
    finally:
        os.chdir(home)
    if status == 130:
        raise KeyboardInterrupt
    return f"solve {' '.join(request['argv'][1:])} -> {status} ({1e3 * (time.perf_counter() - start):.1f} ms)"


def _listen(path):
    """A socket bound to ``path`` (its folder made private; a stale socket replaced, a live one refused)."""
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    if path.exists():
        if not stat.S_ISSOCK(path.stat().st_mode):
            raise InputError(f"{path} exists and is not a socket")
        probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            probe.connect(str(path))
        except OSError:
            path.unlink()
        else:
            raise InputError(f"a server already listens on {path}")
        finally:
            probe.close()
    server = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    server.bind(str(path))
    os.chmod(path, 0o600)
    server.listen(8)
    return server


def _stop(signum, frame):
    raise KeyboardInterrupt


def run(args):
    from startrack.base.allocator import reuse_freed_memory
    from startrack.commands import build_parser

    reuse_freed_memory()  # one request after another
    path = Path(args.socket) if args.socket else socket_path()
    solvers = _SolverCache()
    solvers(build_parser().parse_args(["solve"])).prepare()  # the unknown camera's solver, kernels loaded
    server = _listen(path)
    try:  # a SIGTERM from here on (right after the line that says it listens too) stops the server cleanly
        signal.signal(signal.SIGTERM, _stop)
        version, home = code_version(), os.getcwd()
        # one write of the whole line: a SIGTERM cannot fall between the text and its newline
        sys.stderr.write(f"startrack serve: listening on {path} (code {version}); Ctrl-C stops\n")
        sys.stderr.flush()
        while True:
            connection, _ = server.accept()
            with connection:
                print(f"startrack serve: {_serve(connection, solvers, version, home)}", file=sys.stderr, flush=True)
    except KeyboardInterrupt:
        print("startrack serve: stopped", file=sys.stderr)
    finally:
        server.close()
        path.unlink(missing_ok=True)
    return 0
