"""The client side of ``startrack serve``: a one-shot ``startrack solve`` handed to a running solver.

A new process pays ~1 s before its first solve on a 2-core machine (numpy, scipy and numba imports, the
compiled kernels loaded), the solve itself a few ms.  When a ``startrack serve`` listens on the socket
(:func:`socket_path`) and runs the same code (:func:`code_version`), ``startrack solve`` sends it its
arguments and working directory and prints what the server's ``solve`` prints, as it prints it; else it
solves in its own process as always.  This module imports only the standard library: the client's
whole cost is Python's start and one socket round trip.

Protocol (JSON Lines over a Unix socket, never pickle): the client sends one line ``{"version", "argv",
"cwd"}``; the server answers lines ``{"stdout": text}`` / ``{"stderr": text}`` and a last line
``{"status": n}`` (the exit status), or ``{"refused": reason}`` for other code or another command.
"""

import hashlib
import json
import os
import socket
import sys
from pathlib import Path

#: The socket's path; default ``$XDG_RUNTIME_DIR/startrack/serve.sock``, else under the user cache.
SOCKET_ENV = "STARTRACK_SERVE_SOCKET"
#: Setting it to 0 makes ``startrack solve`` solve in its own process even with a server running.
USE_ENV = "STARTRACK_USE_SERVER"
#: Seconds to wait for a server that does not accept (a stale socket of a killed server: refused at once).
_CONNECT_TIMEOUT_S = 1.0


def socket_path() -> Path:
    explicit = os.environ.get(SOCKET_ENV)
    if explicit:
        return Path(explicit)
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    if runtime:
        return Path(runtime) / "startrack" / "serve.sock"
    base = os.environ.get("STARTRACK_CACHE_DIR") or Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "startrack"
    return Path(base) / "serve.sock"


def code_version() -> str:
    """Digest of the package's source files (path, size, modification time): a server answers only a
    client of the same code."""
    root = Path(__file__).resolve().parent
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        stat = path.stat()
        digest.update(f"{path.relative_to(root)}:{stat.st_size}:{stat.st_mtime_ns};".encode())
    return digest.hexdigest()[:16]


def forwardable(argv) -> bool:
    """A ``solve`` that does not read standard input (``--batch -`` streams from the client's own stdin)."""
    if not argv or argv[0] != "solve" or os.environ.get(USE_ENV) == "0":
        return False
    return not any(a == "-" or a == "--batch=-" for a in argv[1:]) and "-h" not in argv and "--help" not in argv


def _lines(connection):
    buffer = b""
    while True:
        chunk = connection.recv(65536)
        if not chunk:
            return
        buffer += chunk
        *complete, buffer = buffer.split(b"\n")
        for line in complete:
            yield json.loads(line)


def forward(argv):
    """The exit status of ``startrack`` ``argv`` answered by a running server, or None (no server, other
    code, not a forwardable command): then the caller solves in its own process."""
    argv = list(sys.argv[1:] if argv is None else argv)
    path = socket_path()
    if not forwardable(argv) or not path.exists():
        return None
    connection = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    answered = False
    try:
        connection.settimeout(_CONNECT_TIMEOUT_S)
        connection.connect(str(path))
        connection.settimeout(None)
        request = {"version": code_version(), "argv": argv, "cwd": os.getcwd()}
        connection.sendall(json.dumps(request).encode() + b"\n")
        for message in _lines(connection):
            if "refused" in message:
                return None
            if "status" in message:
                return int(message["status"])
            stream = sys.stdout if "stdout" in message else sys.stderr
            stream.write(message.get("stdout", message.get("stderr", "")))
            stream.flush()
            answered = True
    except OSError:  # no server listening (a stale socket), or it went away: solve here if nothing was printed
        pass
    finally:
        connection.close()
    if answered:
        print(f"startrack: error: the server at {path} stopped before the end of its answer", file=sys.stderr)
        return 1
    return None
