"""Where a command writes: checked before any work, and locked while it writes.

`check_folder` and `check_file` refuse an output path that cannot be written -- a file where
a folder is wanted, a folder where a file is wanted, a path under a file, a folder the user
may not write in, a read-only file system -- with one line naming the option, the path and
why, before anything is simulated. They probe by creating (and at once removing) a hidden
temporary entry, so what they report is what the file system does, for any user.

`staged_outputs` gives a command a private folder beside its output folder to write into; the
files move into the output folder only when every one of them was written, so a run that
fails half-way (a full disk, a fault) leaves no file that looks finished, and an earlier run's
files stay whole.

`folder_lock` holds an exclusive lock on ``<folder>/.clearance.lock`` while a command writes
there, so that two commands never mix their files in one folder: the second is refused with
the holder's pid, host, start time and command line. A command replaces only the files it
writes itself and never deletes others; the lock file goes when the lock is released, and a
folder the command created is removed again when the command stops before writing anything.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
import socket
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["LOCK_NAME", "FolderBusyError", "check_file", "check_folder", "folder_lock", "staged_outputs", "write_fault"]

LOCK_NAME = ".clearance.lock"
"""The lock file a command holds in its output folder while it writes there."""


class FolderBusyError(ValueError):
    """Another command holds the output folder's lock."""


def _existing_ancestor(p: Path) -> Path:
    """The nearest ancestor of ``p`` (or ``p``) that exists."""
    a = p
    while not os.path.lexists(a) and a != a.parent:
        a = a.parent
    return a


def _why(err: OSError) -> str:
    return err.strerror or type(err).__name__


def _refuse_broken_link(p: Path, option: str) -> None:
    """Refuse a link that leads nowhere (its target is missing, or links loop)."""
    if p.is_symlink() and not p.exists():
        raise ValueError(f"{option} {p}: is a link to {os.readlink(p)}, which does not exist (or loops)")


def _probe_folder(folder: Path) -> None:
    """Create and remove a hidden temporary file in an existing folder (raises OSError)."""
    fd, tmp = tempfile.mkstemp(prefix=".clearance-probe-", dir=folder)
    os.close(fd)
    os.unlink(tmp)


def _probe_create(ancestor: Path) -> None:
    """Create and remove a hidden temporary folder in an existing folder (raises OSError)."""
    os.rmdir(tempfile.mkdtemp(prefix=".clearance-probe-", dir=ancestor))


def check_folder(path: str | os.PathLike[str], option: str = "--out") -> Path:
    """An output folder that can be created or written in, else a one-line refusal.

    Args:
        path: the folder given (it need not exist yet; nothing is created here).
        option: the option that gave it, for the message.

    Returns:
        The folder as a `Path`.

    Raises:
        ValueError: an empty path; an existing file; a path under a file; a folder that
            cannot be written in or created (the message gives the system's reason).
    """
    if not str(path):
        raise ValueError(f"{option}: give a folder (got an empty path)")
    p = Path(path)
    try:
        _refuse_broken_link(p, option)
        if p.exists():
            if not p.is_dir():
                raise ValueError(f"{option} {p}: is a file, not a folder; give a folder to write the outputs in")
            _check_writable(p, p, option, "this folder")
            return p
        _check_creatable(p, p, option)
    except OSError as err:  # a path the system refuses to look at (too long, a loop, no access)
        raise ValueError(f"{option} {p}: {_why(err)}") from None
    return p


def check_file(path: str | os.PathLike[str], option: str, *, example: str = "out.xml") -> Path:
    """An output file that can be written (atomically, beside itself), else a one-line refusal.

    Args:
        path: the file given (it need not exist; missing parent folders are created later).
        option: the option that gave it, for the message.
        example: a file name for the message when a folder was given.

    Returns:
        The file as a `Path`.

    Raises:
        ValueError: an empty path; an existing folder; a path under a file; a folder that
            cannot be written in or created.
    """
    if not str(path):
        raise ValueError(f"{option}: give a file path (got an empty path)")
    p = Path(path)
    try:
        _refuse_broken_link(p, option)
        if p.is_dir():
            raise ValueError(f"{option} {p}: is a folder; give a file path (e.g. {p / example})")
        parent = p.parent
        if parent.exists():
            if not parent.is_dir():
                raise ValueError(f"{option} {p}: {parent} is a file, not a folder")
            _check_writable(p, parent, option, str(parent))
            return p
        _check_creatable(p, parent, option)
    except OSError as err:
        raise ValueError(f"{option} {p}: {_why(err)}") from None
    return p


def _check_writable(p: Path, folder: Path, option: str, where: str) -> None:
    """Refuse ``p`` when nothing can be written in its existing ``folder``."""
    try:
        _probe_folder(folder)
    except OSError as err:
        raise ValueError(f"{option} {p}: cannot write in {where} ({_why(err)})") from None


def _check_creatable(p: Path, folder: Path, option: str) -> None:
    """Refuse ``p`` when its missing ``folder`` cannot be created under its nearest existing ancestor."""
    a = _existing_ancestor(folder)
    if not a.is_dir():
        raise ValueError(f"{option} {p}: {a} is a file, not a folder, so no folder can be made under it")
    _check_lengths(p, a, option)
    try:
        _probe_create(a)
    except OSError as err:
        raise ValueError(f"{option} {p}: cannot create a folder in {a} ({_why(err)})") from None


def _check_lengths(p: Path, ancestor: Path, option: str) -> None:
    """Refuse a path whose missing part has a name, or which as a whole is, longer than the file system allows."""
    try:
        name_max = os.pathconf(ancestor, "PC_NAME_MAX")
        path_max = os.pathconf(ancestor, "PC_PATH_MAX")
    except (OSError, ValueError):  # the system does not say: the probe and the writes will
        return
    for part in p.relative_to(ancestor).parts if p.is_relative_to(ancestor) else p.parts:
        if len(os.fsencode(part)) > name_max:
            raise ValueError(
                f"{option} {p}: the name '{part[:24]}...' is {len(os.fsencode(part))} bytes long, more than the "
                f"{name_max} the file system allows for one name"
            )
    if len(os.fsencode(os.path.abspath(p))) >= path_max:
        raise ValueError(f"{option} {p}: the path is longer than the {path_max} bytes the file system allows")


def _holder_text(fd: int) -> str:
    try:
        data = json.loads(os.pread(fd, 4096, 0).decode("utf-8"))
        started = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(float(data["started"])))
        return f"pid {data['pid']} on {data['host']}, started {started}: {data['command']}"
    except (OSError, ValueError, KeyError, TypeError):
        return "a command that is just starting"


def _open_locked(lock: Path, folder: Path, option: str) -> int:
    """Open ``lock`` and take its exclusive lock; the fd, or `FolderBusyError`."""
    import fcntl

    while True:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder_text(fd)
            os.close(fd)
            raise FolderBusyError(
                f"{option} {folder}: another clearance command is writing there ({holder}); wait for it to "
                f"finish or give another {option}"
            ) from None
        # the holder before us may have removed the file after we opened it: lock the one on disk
        try:
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)


@contextmanager
def folder_lock(folder: Path, option: str = "--out") -> Iterator[Path]:
    """Create ``folder`` if needed and hold its lock for the ``with`` block.

    Args:
        folder: the output folder (checked with `check_folder` first).
        option: the option that gave it, for the message.

    Yields:
        The folder.

    Raises:
        FolderBusyError: another command holds the lock (a `ValueError`); nothing was
            written or created.

    Where the system has no ``fcntl`` (Windows), the folder is created and not locked. An
    `OSError` raised in the block without a file name (a full disk met by a buffered write) gets
    ``folder`` as its ``filename``, so the message names where the command was writing.
    """
    import importlib.util

    missing = []
    a = folder
    while not a.exists() and a != a.parent:
        missing.append(a)
        a = a.parent
    folder.mkdir(parents=True, exist_ok=True)
    if importlib.util.find_spec("fcntl") is None:
        yield folder
        return
    lock = folder / LOCK_NAME
    try:
        fd = _open_locked(lock, folder, option)
    except BaseException:
        _remove_empty(missing)
        raise
    holder = {
        "pid": os.getpid(),
        "host": socket.gethostname(),
        "started": time.time(),
        "command": " ".join([Path(sys.argv[0]).name, *sys.argv[1:]]) if sys.argv else "?",
    }
    os.ftruncate(fd, 0)
    os.pwrite(fd, json.dumps(holder).encode("utf-8"), 0)
    ok = False
    try:
        yield folder
        ok = True
    except OSError as err:  # a system error that did not say where (a full disk): the folder
        if err.filename is None and err.errno is not None:
            err.filename = str(folder)
        raise
    finally:
        lock.unlink(missing_ok=True)  # while still held: a later command creates a new one
        os.close(fd)
        if not ok:
            _remove_empty(missing)


def _stage_folder(folder: Path) -> Path:
    """A new private folder beside ``folder`` (the same parent, so relative paths from it are the same),
    or inside it where its parent cannot be written."""
    try:
        return Path(tempfile.mkdtemp(prefix=f".{folder.name}.partial-", dir=folder.parent))
    except OSError:
        return Path(tempfile.mkdtemp(prefix=".clearance-partial-", dir=folder))


@contextmanager
def staged_outputs(folder: Path) -> Iterator[Path]:
    """Write a command's files into a private folder; move them into ``folder`` when the block ends well.

    The files move one by one (`os.replace`, on the same file system: nothing is copied), Markdown
    reports last, replacing files of the same names; others in ``folder`` are left alone. When
    the block raises, the private folder and everything in it are removed, so ``folder`` holds
    no file of the failed command.

    Args:
        folder: the output folder (exists; the command holds its lock).

    Yields:
        The private folder to write into.
    """
    stage = _stage_folder(folder)
    try:
        yield stage
        files = sorted((f for f in stage.rglob("*") if f.is_file()), key=lambda f: (f.suffix == ".md", str(f)))
        for f in files:
            dest = folder / f.relative_to(stage)
            dest.parent.mkdir(parents=True, exist_ok=True)
            os.replace(f, dest)
    finally:
        shutil.rmtree(stage, ignore_errors=True)


_WRITE_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM, errno.EIO, errno.EFBIG}
"""System errors that say a file could not be written (a full disk, a read-only or vanished folder)."""


def write_fault(err: OSError) -> str:
    """One line for an `OSError` met while a command wrote its files: which file, and why.

    Args:
        err: the error (its ``filename`` names the file, where the system gave it).

    Returns:
        ``cannot write <file> (<reason>)``, with a remedy for a full disk.
    """
    where = f" {err.filename}" if err.filename else ""
    why = err.strerror or type(err).__name__
    remedy = "; free some space, or give another folder" if err.errno in (errno.ENOSPC, errno.EDQUOT) else ""
    verb = "write" if err.errno in _WRITE_ERRNOS else "use"
    return f"cannot {verb}{where} ({why}){remedy}"


def _remove_empty(created: list[Path]) -> None:
    """Remove the folders this command created (deepest first) if nothing was written in them."""
    for d in created:
        try:
            d.rmdir()
        except OSError:
            return
