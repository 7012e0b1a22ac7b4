"""The files a scene names, read as data: each a regular file (after its links are resolved),
read with a bounded read.

A path to a device (/dev/zero, /dev/stdin), a FIFO or a socket, a folder, or a file larger than
the reader's limit is refused with an InputError naming the scene's field, within the time of
one open: the file is opened without blocking (a FIFO with no writer would wait forever), its
kind taken from the open file (not from the name, which could change in between), and at most
limit + 1 bytes read (st_size is 0 for /dev/zero and says nothing of a device's length).
"""

import os
import stat
from pathlib import Path

from shellform.errors import InputError


def read_bounded(path, field: str, limit: int) -> bytes:
    """The bytes of the regular file `path`, at most `limit` of them; InputError(field) where it
    is missing, not a regular file, unreadable or larger."""
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as err:
        raise InputError(field, f"cannot read {str(path)!r}: {err.strerror or type(err).__name__}") from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            kind = ("a folder" if stat.S_ISDIR(mode) else "a FIFO" if stat.S_ISFIFO(mode) else
                    "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "a socket" if stat.S_ISSOCK(mode)
                    else "not a regular file")
            raise InputError(field, f"{str(path)!r} is {kind}, not a regular file")
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 16, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as err:
        raise InputError(field, f"cannot read {str(path)!r}: {err.strerror or type(err).__name__}") from None
    finally:
        os.close(fd)
    if size > limit:
        raise InputError(field, f"{path.name} is larger than {limit // 1000} kB: no such table is")
    return b"".join(chunks)


def read_text_bounded(path, field: str, limit: int) -> str:
    """read_bounded as UTF-8 text; InputError(field) where it is not."""
    try:
        return read_bounded(path, field, limit).decode("utf-8")
    except UnicodeDecodeError:
        raise InputError(field, f"{Path(path).name} is not UTF-8 text") from None
