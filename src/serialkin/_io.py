"""Atomic file output, shared by every writer: write to a temporary file, then rename.

The temporary file is hidden beside the target, ``.NAME.HOST-PID.XXXXXXXX.tmp``, where
HOST is a short hash of the machine's name and PID the writer's process id. A writer
killed between creating it and renaming it (``kill -9``, power loss) leaves it behind;
the next atomic write of the same target removes such stale files: those of a process
of this machine that no longer runs, and any (also from other machines or older
versions, ``.NAME.XXXXXXXX.tmp``) not modified for :data:`STALE_AFTER` seconds. The
temporary file of a writer that still runs is never touched, so concurrent writers of
one target do not break each other (the last rename wins).
"""

from __future__ import annotations

import hashlib
import os
import re
import socket
import stat
import tempfile
import time
from pathlib import Path

from serialkin.errors import OutputError

#: Age [s] after which any leftover temporary file of a target is removed.
STALE_AFTER = 24 * 3600.0


def write_bytes_atomic(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder and a rename.

    An interrupted run never leaves a truncated file: readers see the old file or the new
    one. Parent folders are created. Stale temporary files of earlier, killed writes of
    the same target are removed first (see the module docstring).

    Only regular files are replaced. A symbolic link is followed on purpose: the file it
    points to is replaced and the link kept (a dangling link's target is created). A
    character device or a FIFO (``/dev/null``, ``/dev/stdout``, a named pipe) is written
    through, never replaced. A folder, a block device or a socket is refused.

    Raises:
        OutputError: the folder cannot be created or written, or the path is a folder, a
            block device or a socket (the message names the path).
    """
    out = Path(path)
    if os.path.islink(out):
        out = Path(os.path.realpath(out))  # replace the link's target, keep the link
    mode = _mode(out)
    if mode is not None and not stat.S_ISREG(mode):
        if _is_stream(mode):
            try:
                with open(out, "wb") as f:  # write through: a device is never replaced
                    f.write(data)
            except OSError as exc:
                raise OutputError(f"cannot write {str(out)!r}: {exc.strerror or exc}") \
                    from exc
            return out
        kind = "a folder" if stat.S_ISDIR(mode) else "not a regular file"
        raise OutputError(f"cannot write {str(out)!r}: it is {kind}; serialkin writes "
                          "regular files, devices and pipes only")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        remove_stale_temporaries(out)
        fd, tmp = tempfile.mkstemp(dir=out.parent, prefix=f".{_stem(out)}.{_writer_tag()}.",
                                   suffix=".tmp")
    except OSError as exc:
        raise OutputError(f"cannot write {str(out)!r}: {exc.strerror or exc}") from exc
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp creates 0600; give the usual mode
        os.replace(tmp, out)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise OutputError(f"cannot write {str(out)!r}: {exc.strerror or exc}") from exc
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise
    return out


def _mode(path: str | Path) -> int | None:
    """``st_mode`` of ``path`` (links followed), or None when it cannot be seen."""
    try:
        return os.stat(path).st_mode
    except OSError:
        return None  # a new file (or one we cannot see: a write says why)


def _is_stream(mode: int) -> bool:
    return stat.S_ISCHR(mode) or stat.S_ISFIFO(mode)


def written_through(path: str | Path) -> bool:
    """Whether ``path`` is a character device or a FIFO, which writes go through to."""
    mode = _mode(path)
    return mode is not None and _is_stream(mode)


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically (see :func:`write_bytes_atomic`)."""
    return write_bytes_atomic(path, text.encode("utf-8"))


def remove_stale_temporaries(target: str | Path, *, now: float | None = None) -> list[Path]:
    """Remove the stale temporary files that killed writes of ``target`` left beside it.

    A temporary file ``.NAME.HOST-PID.XXXXXXXX.tmp`` is stale when HOST is this machine
    and process PID no longer runs (PID reuse only delays the removal), or when it has
    not been modified for :data:`STALE_AFTER` seconds; an old-style
    ``.NAME.XXXXXXXX.tmp`` only by age. Files of running writers are kept. Errors
    (a file removed meanwhile by another writer, a folder that cannot be listed) are
    ignored: cleaning up never makes a write fail.

    Args:
        target: the file whose leftovers are removed.
        now: the current time [s since the epoch] (default: the clock).

    Returns:
        The files removed.
    """
    out = Path(target)
    pattern = re.compile(re.escape(f".{_stem(out)}.") +
                         r"(?:(?P<host>[0-9a-f]{8})-(?P<pid>[0-9]+)\.)?[A-Za-z0-9_]{8}\.tmp\Z")
    now = time.time() if now is None else now
    removed: list[Path] = []
    try:
        entries = list(os.scandir(out.parent))
    except OSError:
        return removed
    me = _host_tag()
    for entry in entries:
        m = pattern.match(entry.name)
        if m is None:
            continue
        try:
            age = now - entry.stat(follow_symlinks=False).st_mtime
            pid = int(m["pid"]) if m["pid"] is not None else None
            dead = (pid is not None and m["host"] == me and pid != os.getpid()
                    and not _process_runs(pid))
            if dead or age > STALE_AFTER:
                os.unlink(entry.path)
                removed.append(Path(entry.path))
        except (OSError, ValueError):
            continue
    return removed


def _stem(out: Path) -> str:
    """The target's name as used in its temporary files (cut so they fit in 255 bytes)."""
    name = out.name
    while len(name.encode("utf-8", "surrogateescape")) > 200:
        name = name[: len(name) // 2]
    return name


def _process_runs(pid: int) -> bool:
    """True when process ``pid`` exists on this machine (whoever owns it)."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, OSError):
        return True  # exists but belongs to another user, or cannot tell: keep the file
    return True


_HOST_TAG: str | None = None


def _host_tag() -> str:
    """8 hex digits identifying this machine (a hash of its host name)."""
    global _HOST_TAG
    if _HOST_TAG is None:
        _HOST_TAG = hashlib.sha256(socket.gethostname().encode("utf-8", "replace")
                                   ).hexdigest()[:8]
    return _HOST_TAG


def _writer_tag() -> str:
    return f"{_host_tag()}-{os.getpid()}"


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
