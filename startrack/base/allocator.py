"""The memory of a long-lived solver (a stream of frames, ``startrack serve``): freed image buffers reused.

glibc serves an allocation above its mmap threshold (128 kB, growing to the largest block freed) with fresh
pages from the kernel and returns them on free, so a process that reads and detects one frame after another
takes a page fault on every page of every image-sized array of every frame: measured on the 1024 x 768
real frames, 3.7 ms of the 5.9 ms a ``startrack solve --batch -`` stream added per frame to the same
reading, detection and solve in a process that had already raised its threshold.  :func:`reuse_freed_memory`
sets the threshold to glibc's largest (32 MiB: a 2000 x 2000 float64 frame) and keeps up to twice that free
at the heap's top (``mallopt``, glibc's malloc.h); elsewhere it does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import sys

#: mallopt's parameter numbers (glibc malloc.h).
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
#: Largest allocation served from the heap [bytes] (glibc's limit on 64-bit) and the free heap top kept.
_MMAP_THRESHOLD = 32 << 20
_TRIM_THRESHOLD = 2 * _MMAP_THRESHOLD


def reuse_freed_memory() -> bool:
    """Have glibc serve allocations up to :data:`_MMAP_THRESHOLD` from the heap and keep freed memory for the
    next frame (module text); whether it applied (glibc on Linux only)."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6").mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, _MMAP_THRESHOLD)) and bool(mallopt(_M_TRIM_THRESHOLD, _TRIM_THRESHOLD))
