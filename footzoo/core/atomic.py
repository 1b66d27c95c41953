"""Atomic output files: every file footzoo writes appears complete under its final name, or not at all.

A file is written to a temporary name in its target folder (``.<name>.footzoo-tmp-<random>``),
flushed to disk, and renamed into place (:func:`os.replace`, atomic on POSIX and Windows within one
file system). An interrupt (Ctrl-C) or a crash while writing leaves the old file untouched and no
partial file under the final name; the temporary file is removed on any error.

Files that belong together (a recording and its sidecars; the tables of a result) are written as
one :class:`FileGroup`: every member is written first, then all are renamed, with Ctrl-C deferred
until the renames are done; files of an earlier version that the new one no longer has (a stale
sidecar) are removed in the same step.

No output may replace an input: :func:`refuse_inputs` compares each target with every input by
file identity (same inode and device: symlinks, ``..`` and hard links included) and raises
:class:`~footzoo.core.errors.OutputError` naming both.

Usage::

    from footzoo.core.atomic import FileGroup, atomic_path, atomic_write, write_json

    with atomic_write("notes.txt") as fh:          # a text (or "wb": binary) file handle
        fh.write("...")
    with atomic_path("figure.png") as tmp:         # a temporary path, for writers that take a path
        fig.savefig(tmp, format="png")
    write_json("metrics.json", {"rmse_m": float("nan")})   # strict JSON: NaN -> null
    with FileGroup(inputs=[data_file]) as group:   # several files, committed together
        frame.to_csv(group.path("walk.csv"))
        group.path("walk.csv.meta.yaml").write_text(text)
        group.remove("walk.csv.steps.csv")         # a stale sidecar of the earlier file

Writers pass the recording's input files as ``inputs`` so that ``--out`` pointing at the data is
refused before anything is written.
"""

from __future__ import annotations

import contextlib
import errno
import json
import math
import os
import secrets
import signal
import socket
import threading
import time
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import IO, Any

from .._version import __version__
from .errors import FormatError, OutputError
from .files import nul_in_path

#: Infix of the temporary files (a leftover one, from a killed process, can be deleted).
TMP_INFIX = ".footzoo-tmp-"

PathLike = str | os.PathLike


#: Age (s) from which a temporary file is a leftover of a killed writer: no single file takes an hour to write.
STALE_TEMPORARY = 3600.0


def _temporary_name(target: Path) -> Path:
    return target.with_name(f".{target.name}{TMP_INFIX}{secrets.token_hex(4)}")


def remove_stale_temporaries(folder: Path, name: str = "*") -> None:
    """Remove the temporary files (``.<name>.footzoo-tmp-*``, ``name`` a glob) in ``folder`` that a writer killed
    before it could rename or remove them left behind: those older than :data:`STALE_TEMPORARY` s (a running
    writer's are younger). Called once per command: when an output folder is locked, and by the recording writer
    for its files.
    """
    now = time.time()
    for tmp in folder.glob(f".{name}{TMP_INFIX}*"):
        with contextlib.suppress(OSError):  # gone meanwhile, or not ours to remove
            if tmp.is_file() and not tmp.is_symlink() and now - tmp.stat().st_mtime > STALE_TEMPORARY:
                tmp.unlink()


def check_target(path: PathLike, what: str = "output") -> Path:
    """``path`` as a :class:`~pathlib.Path` a file can be written to, or an :class:`OutputError` saying why not.

    Refuses an empty path, a directory, a missing folder and a folder without write permission,
    before any work is done.
    """
    if not isinstance(path, (str, os.PathLike)):
        raise OutputError(f"{what} must be a file path (str or Path), got {type(path).__name__} {path!r:.80}")
    if not str(path).strip():
        raise OutputError(f"{what} is an empty path; give a file name")
    if nul_in_path(path):
        raise OutputError(f"{what} {nul_in_path(path)}")
    p = Path(path)
    if p.is_dir():
        raise OutputError(f"{what} {str(p)!r} is a directory; give a file name")
    folder = p.parent
    if not folder.is_dir():
        raise OutputError(f"{what} {str(p)!r}: the folder {str(folder)!r} does not exist; create it first")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{what} {str(p)!r} is not writable (permission denied on {str(folder)!r}); "
                          "choose a writable place")
    return p


def same_file(a: PathLike, b: PathLike) -> bool:
    """True when ``a`` and ``b`` name the same existing file (symlinks, ``..``, hard links resolved)."""
    try:
        return os.path.samefile(a, b)
    except OSError:  # one of them does not exist (or is unreadable): nothing to clobber
        return False


def refuse_inputs(targets: Iterable[PathLike], inputs: Iterable[PathLike], what: str = "output") -> None:
    """Raise :class:`OutputError` when a target file is one of the inputs.

    Parameters
    ----------
    targets : iterable of paths
        Files about to be written (or removed).
    inputs : iterable of paths
        Files the run read (recording, sidecars, reference files, configs).
    what : str
        How the output was named (``"--out"``, ``"Result.save path"``), for the message.
    """
    inputs = [Path(i) for i in inputs if i is not None and str(i)]
    for target in targets:
        for source in inputs:
            if same_file(target, source):
                raise OutputError(
                    f"{what} would overwrite the input {str(source)!r} (the output {str(target)!r} is that file); "
                    "choose another output location: footzoo never replaces its inputs"
                )


_DEFERRING = threading.local()


@contextlib.contextmanager
def _interrupts_deferred() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) until the block has finished; re-raise it afterwards (main thread only)."""
    if threading.current_thread() is not threading.main_thread() or getattr(_DEFERRING, "on", False):
        yield  # not the main thread (no signals here), or already held by an enclosing block
        return
    caught: list[Any] = []
    try:
        previous = signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    except (ValueError, OSError):  # no signal handling here (embedded interpreter)
        yield
        return
    _DEFERRING.on = True
    try:
        yield
    finally:
        _DEFERRING.on = False
        signal.signal(signal.SIGINT, previous)
        if caught:
            raise KeyboardInterrupt


def _fsync_folder(folder: Path) -> None:
    """Make the renames in ``folder`` durable (POSIX; a no-op where folders cannot be opened)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _remove_quietly(path: Path) -> None:
    with contextlib.suppress(FileNotFoundError):
        path.unlink()


def _os_error(err: OSError, target: Path) -> OutputError:
    if err.errno in (errno.EACCES, errno.EPERM):
        return OutputError(f"{str(target)!r} cannot be written (permission denied); choose a writable place")
    if err.errno == errno.ENOSPC:
        return OutputError(f"{str(target)!r} cannot be written: no space left on the device; the old file is kept")
    return OutputError(f"{str(target)!r} cannot be written: {err.strerror or err}")


class FileGroup:
    """Files written together and renamed into place together (a data file and its sidecars).

    Parameters
    ----------
    inputs : iterable of paths
        Files that must not be replaced (the run's inputs); checked at every :meth:`path` and :meth:`remove`.
    what : str
        How the output was named, for messages.
    fsync : bool
        Flush every file (and the folders' entries) to disk before returning. ``False`` is faster where
        durability against a power cut does not matter (a cache that is recomputed when damaged).
    marker : path, optional
        The member that is the folder's completion marker (a manifest): the earlier one is set aside
        before the other members are renamed, and the new one is renamed last
        (:func:`begin_folder`), so that even a process killed half-way through the renames leaves a
        folder its readers refuse as incomplete, never one that mixes two versions and looks whole.

    Notes
    -----
    Use it as a context manager: on a normal exit every member is renamed into place and every
    file passed to :meth:`remove` deleted; on an exception (Ctrl-C included) the temporary files are
    deleted and nothing under a final name changes.
    """

    def __init__(self, inputs: Iterable[PathLike] = (), what: str = "output", fsync: bool = True,
                 marker: PathLike | None = None):
        self.inputs = [Path(i) for i in inputs]
        self.what = what
        self.fsync = fsync
        self.marker = Path(os.path.abspath(marker)) if marker is not None else None
        self._members: dict[Path, Path] = {}
        self._stale: list[Path] = []
        self._done = False

    def path(self, target: PathLike) -> Path:
        """The temporary path to write ``target`` to (created empty, in ``target``'s folder)."""
        t = check_target(target, self.what)
        refuse_inputs([t], self.inputs, self.what)
        key = Path(os.path.abspath(t))
        if key in self._members:
            return self._members[key]
        tmp = _temporary_name(t)
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # the umask applies, as for any file
            os.close(fd)
        except OSError as err:
            raise _os_error(err, t) from None
        self._members[key] = tmp
        return tmp

    @contextlib.contextmanager
    def open(self, target: PathLike, mode: str = "w", encoding: str | None = "utf-8",
             newline: str | None = None) -> Iterator[IO[Any]]:
        """A file handle on the temporary file of ``target`` (``"w"`` text, ``"wb"`` binary)."""
        if mode not in ("w", "wb"):
            raise ValueError(f"mode must be 'w' or 'wb', got {mode!r}")
        tmp = self.path(target)
        kwargs = {} if "b" in mode else {"encoding": encoding, "newline": newline}
        try:
            with open(tmp, mode, **kwargs) as fh:
                yield fh
                fh.flush()
                if self.fsync:
                    os.fsync(fh.fileno())
        except OutputError:
            raise
        except OSError as err:  # the disk full while writing, a quota: named, the old file kept (the group aborts)
            raise _os_error(err, Path(target)) from None

    def forget(self, target: PathLike) -> None:
        """Drop ``target`` from the group (its temporary file is deleted; the final file is left as it is)."""
        key = Path(os.path.abspath(target))
        tmp = self._members.pop(key, None)
        if tmp is not None:
            _remove_quietly(tmp)

    def remove(self, target: PathLike) -> None:
        """Delete ``target`` (if it exists) when the group commits: a sidecar the new version no longer has."""
        t = Path(target)
        refuse_inputs([t], self.inputs, self.what)
        self._stale.append(t)

    def commit(self) -> list[Path]:
        """Rename every member into place and delete the stale files; returns the final paths."""
        if self._done:
            raise RuntimeError("this FileGroup was already committed or aborted")
        done: list[Path] = []
        with _interrupts_deferred():
            try:
                if self.fsync:
                    for tmp in self._members.values():
                        _fsync_file(tmp)
                marked = self.marker is not None and self.marker in self._members
                if marked:
                    begin_folder(self.marker.parent, self.marker.name)
                for final, tmp in self._members.items():
                    if final != self.marker or not marked:
                        os.replace(tmp, final)
                        done.append(final)
                for stale in self._stale:
                    if Path(os.path.abspath(stale)) not in self._members:
                        _remove_quietly(stale)
                if marked:
                    os.replace(self._members[self.marker], self.marker)
                    done.append(self.marker)
                    _remove_quietly(self.marker.parent / INCOMPLETE)
            except OSError as err:
                self._discard()
                written = f" ({', '.join(p.name for p in done)} already replaced)" if done else ""
                raise OutputError(f"{self.what}: renaming the new files into place failed{written}: "
                                  f"{err.strerror or err}") from None
            finally:
                self._done = True
            if self.fsync:
                for folder in {p.parent for p in done} | {s.parent for s in self._stale}:
                    _fsync_folder(folder)
        return done

    def abort(self) -> None:
        """Delete the temporary files; nothing under a final name changes."""
        self._discard()
        self._done = True

    def _discard(self) -> None:
        for tmp in self._members.values():
            _remove_quietly(tmp)

    def __enter__(self) -> FileGroup:
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        if self._done:
            return
        if exc_type is None:
            self.commit()
        else:
            self.abort()


def _fsync_file(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_path(path: PathLike, inputs: Iterable[PathLike] = (), what: str = "output",
                fsync: bool = True) -> Iterator[Path]:
    """A temporary path for ``path``, renamed into place when the block ends without an error.

    For writers that take a file name (``DataFrame.to_parquet``, ``Figure.savefig``, ``np.savez``).
    The writer must not add its own extension (pass ``format=`` where it would: ``savefig(tmp,
    format="png")``; ``np.savez`` with an open file handle).
    """
    with FileGroup(inputs=inputs, what=what, fsync=fsync) as group:
        yield group.path(path)


@contextlib.contextmanager
def atomic_write(path: PathLike, mode: str = "w", encoding: str | None = "utf-8", newline: str | None = None,
                 inputs: Iterable[PathLike] = (), what: str = "output", fsync: bool = True) -> Iterator[IO[Any]]:
    """A file handle whose content replaces ``path`` only once the block ends without an error.

    Parameters
    ----------
    path : path
        The final file.
    mode : {"w", "wb"}
        Text or binary.
    encoding, newline : str, optional
        As for :func:`open` (text mode).
    inputs : iterable of paths
        Files that must not be replaced (:func:`refuse_inputs`).
    what : str
        How the output was named, for messages.
    fsync : bool
        Flush to disk before the rename.
    """
    with FileGroup(inputs=inputs, what=what, fsync=fsync) as group, \
            group.open(path, mode, encoding=encoding, newline=newline) as fh:
        yield fh


def write_text(path: PathLike, text: str, inputs: Iterable[PathLike] = (), what: str = "output",
               encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` atomically; returns the path."""
    with atomic_write(path, "w", encoding=encoding, inputs=inputs, what=what) as fh:
        fh.write(text)
    return Path(path)


def write_bytes(path: PathLike, data: bytes, inputs: Iterable[PathLike] = (), what: str = "output") -> Path:
    """Write ``data`` to ``path`` atomically; returns the path."""
    with atomic_write(path, "wb", inputs=inputs, what=what) as fh:
        fh.write(data)
    return Path(path)


def json_safe(value: Any) -> Any:
    """``value`` as plain JSON data: NaN and ±inf -> None, numpy scalars and arrays -> numbers and lists.

    Mappings keep their keys (as strings), tuples and sets become lists, paths and other objects
    their ``str``.
    """
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, set, frozenset)):
        return [json_safe(v) for v in value]
    tolist = getattr(value, "tolist", None)  # numpy scalars and arrays, pandas objects
    if callable(tolist):
        return json_safe(tolist())
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return str(value)


def dumps_json(value: Any, indent: int | None = 2) -> str:
    """Strict JSON text of ``value`` (:func:`json_safe` first: no bare ``NaN`` or ``Infinity``)."""
    return json.dumps(json_safe(value), indent=indent, allow_nan=False, ensure_ascii=False) + "\n"


def write_json(path: PathLike, value: Any, inputs: Iterable[PathLike] = (), what: str = "output",
               indent: int | None = 2) -> Path:
    """Write ``value`` as strict JSON (NaN -> null) to ``path`` atomically; returns the path."""
    return write_text(path, dumps_json(value, indent), inputs=inputs, what=what)


#: Lock file an output folder holds while one footzoo process writes into it (:func:`folder_lock`).
LOCK_NAME = ".footzoo.lock"

_HELD: dict[tuple[str, int], int] = {}  # (folder, thread) -> depth: the locks this process holds
_HELD_LOCK = threading.Lock()


@contextlib.contextmanager
def folder_lock(folder: PathLike, what: str = "output folder", owner: str = "",
                identity: str | None = None) -> Iterator[Path]:
    """Hold a lock on ``folder`` (the file ``.footzoo.lock`` in it) for the block.

    The lock file says who holds it: ``owner`` (e.g. ``"study 'quick'"``), the process id, the host
    and the start time. Another footzoo process that asks for the same folder gets an
    :class:`OutputError` at once (it does not wait) naming the holder and how to proceed, unless
    both give the same ``identity`` (the same study started twice: they share its cache, resume
    each other's runs and write the same report). The lock is released when the block ends (its
    file removed by the last holder); a process that dies holding it releases it too (the operating
    system drops an ``flock`` with its process), so a lock left by a killed process is stale and
    taken over. Where the file system has no locks (some network file systems), the lock file's
    process id decides: a holder on this host that no longer runs is stale. The same thread may
    enter the lock again (a tune runs its studies in its own folder).

    Parameters
    ----------
    folder : path
        The output folder (created when missing).
    what : str
        How the folder was named (``"--out"``), for messages.
    owner : str
        What writes into it, for the message another process gets.
    identity : str, optional
        What the holder writes: processes with the same identity share the folder; None: exclusive.
    """
    p = Path(folder)
    try:
        p.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        fix = ("it is a file, and the output is a folder: give a folder name, or move the file away"
               if p.exists() and not p.is_dir() else "choose a folder you can write to")
        raise OutputError(f"{what} {str(p)!r} cannot be created: {err.strerror or err}; {fix}") from None
    key = (os.path.realpath(p), threading.get_ident())
    with _HELD_LOCK:
        nested = key in _HELD
        if nested:
            _HELD[key] += 1
    if nested:
        try:
            yield p
        finally:
            with _HELD_LOCK:
                _HELD[key] -= 1
        return
    fh = _acquire(p, what, owner, identity)
    remove_stale_temporaries(p)  # a killed writer's leftovers in the folder
    with _HELD_LOCK:
        _HELD[key] = 1
    try:
        yield p
    finally:
        with _HELD_LOCK:
            _HELD.pop(key, None)
        if identity is None or _try_lock(fh) is True:  # the last holder: no other process holds this file
            with contextlib.suppress(OSError):
                os.unlink(p / LOCK_NAME)
            fh.close()  # closing releases the lock
        else:
            fh.close()
            _remove_if_unheld(p / LOCK_NAME)  # the others may have left while this one looked


def _remove_if_unheld(lock: Path) -> None:
    """Remove the lock file ``lock`` if no holder is left (two holders of one study leaving at once).

    Each of them may see the other still holding it; each then closes its own handle and looks once more
    with a fresh one, so the last to look finds it free and removes it.
    """
    try:
        fh = open(lock, "r+", encoding="utf-8")  # noqa: SIM115 (closed below, after the removal)
    except OSError:
        return  # already removed
    try:
        if _try_lock(fh) is True and _same_file(fh, lock):
            with contextlib.suppress(OSError):
                os.unlink(lock)
    finally:
        fh.close()


def lock_holder(folder: PathLike) -> dict[str, Any] | None:
    """What the lock file of ``folder`` says about its holder (``pid``, ``host``, ``started``, ``owner``), or None."""
    try:
        text = (Path(folder) / LOCK_NAME).read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    try:
        info = json.loads(text)
    except ValueError:
        return {"owner": text.strip()[:200]} if text.strip() else None
    return info if isinstance(info, dict) else None


def _acquire(folder: Path, what: str, owner: str, identity: str | None) -> IO[Any]:
    """The open, locked lock file of ``folder`` (see :func:`folder_lock`)."""
    lock = folder / LOCK_NAME
    for _ in range(40):  # another process may replace the file, or convert its lock, meanwhile: look again
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as err:
            raise OutputError(f"{what} {str(folder)!r}: its lock file {LOCK_NAME} cannot be created "
                              f"({err.strerror or err}); choose a writable folder") from None
        fh = os.fdopen(fd, "r+", encoding="utf-8")
        state = _try_lock(fh)
        holder = lock_holder(folder)
        shared = identity is not None and (holder or {}).get("identity") == identity
        if state is None and _holder_alive(holder) and not shared:  # no file locks here: the pid decides
            fh.close()
            raise OutputError(_in_use(folder, what, holder, flock=False))
        if state is False:
            if holder is None and identity is not None:  # the holder is starting: its description is not written yet
                fh.close()
                time.sleep(0.05)
                continue
            if not shared:
                fh.close()
                raise OutputError(_in_use(folder, what, holder, flock=True))
            if _try_lock(fh, exclusive=False) is not True:  # the same study, still converting its lock: again
                fh.close()
                time.sleep(0.05)
                continue
        if not _same_file(fh, lock) or (state is False and (lock_holder(folder) or {}).get("identity") != identity):
            fh.close()
            continue
        if state is False:  # sharing the folder with the same study: its description stays
            return fh
        fh.seek(0)
        fh.truncate()
        fh.write(json.dumps({"owner": owner or "footzoo", "pid": os.getpid(), "host": _host(),
                             "started": time.strftime("%Y-%m-%d %H:%M:%S"), "footzoo": _version(),
                             "identity": identity}) + "\n")
        fh.flush()
        if identity is not None and state is True:
            _try_lock(fh, exclusive=False, wait=True)  # the same study may join
        return fh
    raise OutputError(f"{what} {str(folder)!r}: its lock file {LOCK_NAME} keeps changing; another process is "
                      "starting in it: try again")


def _same_file(fh: IO[Any], path: Path) -> bool:
    """Whether the open lock file is still the one at ``path`` (another holder may have removed it meanwhile)."""
    try:
        return os.path.samestat(os.fstat(fh.fileno()), os.stat(path))
    except OSError:
        return False


def _in_use(folder: Path, what: str, holder: dict[str, Any] | None, flock: bool) -> str:
    holder = holder or {}
    who = holder.get("owner") or "another footzoo process"
    where = " ".join(x for x in (f"process {holder['pid']}" if holder.get("pid") else "",
                                 f"on {holder['host']}" if holder.get("host") else "",
                                 f"since {holder['started']}" if holder.get("started") else "") if x)
    stale = "" if flock else (f". If that process no longer runs (on another machine footzoo cannot tell), delete "
                              f"{str(folder / LOCK_NAME)!r} and start again")
    return (f"{what} {str(folder)!r} is in use: {who}{f' ({where})' if where else ''} is writing into it. Wait until "
            f"it has finished, or give this one another output folder{stale}")


def _holder_alive(holder: dict[str, Any] | None) -> bool:
    """Whether the process a lock file names may still run (without file locks: its pid, on this host)."""
    if not holder or not isinstance(holder.get("pid"), int):
        return False
    if holder.get("host") != _host():
        return True  # another machine: footzoo cannot tell, so the lock stands
    try:
        os.kill(holder["pid"], 0)
    except ProcessLookupError:
        return False
    except OSError:  # it exists (owned by another user)
        return True
    return True


def _host() -> str:
    return socket.gethostname()


def _version() -> str:
    return __version__


def _try_lock(fh: IO[Any], exclusive: bool = True, wait: bool = False) -> bool | None:
    """True: locked; False: another process holds a conflicting lock; None: the file system has no locks.

    ``exclusive=False``: a shared lock (compatible with other shared ones; Windows has none: exclusive).
    ``wait``: block until it is granted (converting a lock this process holds).
    """
    try:
        # deferred: the platform's own locking module (fcntl on POSIX, msvcrt on Windows)
        import fcntl
    except ImportError:  # Windows
        import msvcrt

        try:
            msvcrt.locking(fh.fileno(), msvcrt.LK_NBLCK, 1)
            return True
        except OSError:
            return False
    flags = (fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH) | (0 if wait else fcntl.LOCK_NB)
    try:
        fcntl.flock(fh.fileno(), flags)
        return True
    except OSError as err:
        if err.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
            return False
        return None  # ENOLCK, EOPNOTSUPP...: no locks here; the lock file's pid decides


# --------------------------------------------------------------------------- folder outputs

#: Present in a folder output while footzoo (re)writes it; holds the completion marker of the earlier
#: version (the marker is absent meanwhile). A folder with it was interrupted: it is incomplete.
INCOMPLETE = ".footzoo-incomplete"


def begin_folder(folder: PathLike, marker: str) -> Any:
    """Mark the folder output ``folder`` as being written: its completion marker ``marker`` is set aside.

    The marker (a JSON file written last, e.g. a result's ``manifest.json``) is renamed to
    :data:`INCOMPLETE`, so that until :func:`end_folder` writes the new one, readers refuse the
    folder as incomplete (:func:`check_complete`). Returns the earlier marker's content (parsed
    JSON; from :data:`INCOMPLETE` when an earlier write was interrupted), or None.
    """
    f = Path(folder)
    earlier = f / marker
    journal = f / INCOMPLETE
    if earlier.is_file():
        os.replace(earlier, journal)
    elif not journal.exists():
        journal.write_text("{}\n", encoding="utf-8")  # its presence is the mark; the content is the earlier marker
    return previous_marker(f, marker)


def previous_marker(folder: PathLike, marker: str) -> Any:
    """The content of ``folder``'s completion marker, or of the one an interrupted write set aside; None."""
    for name in (marker, INCOMPLETE):
        try:
            data = json.loads((Path(folder) / name).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if data:
            return data
    return None


def end_folder(folder: PathLike, marker: str, text: str | None = None) -> Path:
    """Write the completion marker ``marker`` (last, atomically) and clear the mark of :func:`begin_folder`.

    ``text`` None: put the earlier marker back as it was (nothing changed), when it is still set aside.
    """
    f = Path(folder)
    if text is None:
        with contextlib.suppress(FileNotFoundError):  # another run of the same study may have put it back
            os.replace(f / INCOMPLETE, f / marker)
    else:
        write_text(f / marker, text, what=str(f))
        with contextlib.suppress(FileNotFoundError):
            os.unlink(f / INCOMPLETE)
    _fsync_folder(f)
    return f / marker


def incomplete(folder: PathLike) -> bool:
    """True when a write of the folder output ``folder`` was interrupted (:data:`INCOMPLETE` is there)."""
    return (Path(folder) / INCOMPLETE).exists()


def check_complete(folder: PathLike, marker: str, what: str) -> Path:
    """``folder`` when its completion marker is there and no write was interrupted; else a FormatError."""
    f = Path(folder)
    if incomplete(f):
        raise FormatError(f"{str(f)!r} is incomplete: footzoo was interrupted while writing {what} there "
                          f"({INCOMPLETE} is there, {marker} is not written yet); its files are not all of one "
                          "run: run the command again to complete it")
    if not (f / marker).is_file():
        raise FormatError(f"{str(f)!r} holds no {marker}: it is not {what} written by footzoo, or its writing "
                          f"stopped before the end ({marker} is written last); write it again")
    return f


__all__ = ["INCOMPLETE", "LOCK_NAME", "STALE_TEMPORARY", "TMP_INFIX", "FileGroup", "OutputError", "atomic_path",
           "atomic_write", "begin_folder", "check_complete", "check_target", "dumps_json", "end_folder", "folder_lock",
           "incomplete", "json_safe", "lock_holder", "previous_marker", "refuse_inputs", "remove_stale_temporaries",
           "same_file", "write_bytes", "write_json", "write_text"]
