"""The files and folders the course's commands write and read, shared by the term's tooling and
the grader.

:class:`StagedFolder` makes a run all or nothing: the files are written into a
temporary folder beside the target, and only a run that finished swaps it in
(the previous folder is then removed whole, so no file of an earlier run
stays). A run that fails, raises or is interrupted leaves an existing folder
exactly as it was. A folder that is not empty and has no :data:`MANIFEST`
written by ``uio-teach`` is never replaced: it does not look like an earlier
output, and it may hold someone's work. :func:`write_manifest` records what a
run used and made (the configuration and its hash, the versions, every file
with its SHA-256, :func:`sha256_file`).

:class:`StagedFolder` is the one way the course's commands write a folder
(``figures``, ``labs`` and the graders' feedback): it also holds a
:class:`FolderLock` (one run per folder at a time), removes what killed runs
left beside the folder (:func:`clean_leftovers`), gives the folder the user's
usual permissions and swaps it in with one atomic exchange on Linux, so a run
killed at any point leaves the old set or the new set of files, never a mix.
:func:`prepare_output_dir` creates a folder or says, in one line, why it cannot.

:func:`default_book_dir` says where the book's chapters are (a checkout's
``book/`` or the copy a wheel installs): the lab notebooks are written from
them and the grader reads its checks from them.

The term's tooling (:mod:`uio_teach.instructor`) and the grader
(:mod:`uio_teach.grading`) both build on this module, and neither imports the
other (only the command line ties them together).

Examples
--------
>>> from uio_teach.folders import MANIFEST
>>> MANIFEST
'manifest.json'
"""

from __future__ import annotations

import ctypes
import errno
import glob
import hashlib
import json
import os
import shutil
import sys
import tempfile
from collections.abc import Mapping
from importlib import metadata
from pathlib import Path
from typing import Any

from . import __version__
from .errors import UIOTeachError

__all__ = [
    "MANIFEST",
    "PACKAGED_COURSE",
    "OutputError",
    "FolderBusy",
    "StagedFolder",
    "FolderLock",
    "clean_leftovers",
    "prepare_output_dir",
    "write_manifest",
    "read_manifest",
    "check_output_folder",
    "sha256_file",
    "library_versions",
    "default_book_dir",
]

MANIFEST = "manifest.json"
"""The name of the manifest every run of ``uio-teach figures``, ``labs`` and ``grade`` writes into
its folder."""

PACKAGED_COURSE = Path(__file__).resolve().parent / "_course"
"""Where an installed wheel keeps ``book/*.md``, ``_toc.yml`` and ``references.bib``."""

_LIBRARIES = ("numpy", "scipy", "control", "matplotlib", "cvxpy")


class OutputError(UIOTeachError, OSError):
    """The output folder cannot be created or written to."""


class FolderBusy(OutputError):
    """Another process holds the lock of the output folder (see :class:`FolderLock`)."""


def prepare_output_dir(out: str | os.PathLike[str]) -> Path:
    """Create the output folder if needed and make sure files can be written into it.

    Parameters
    ----------
    out : str or path-like
        The folder.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    OutputError
        The folder cannot be created, is a file, or is not writable; the
        message is one line.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.folders import prepare_output_dir, OutputError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     prepare_output_dir(pathlib.Path(tmp) / "new" / "folder").is_dir()
    True
    >>> with tempfile.NamedTemporaryFile() as f:
    ...     try:
    ...         prepare_output_dir(pathlib.Path(f.name) / "sub")
    ...     except OutputError as err:
    ...         print("cannot create" in str(err))
    True
    """
    path = Path(out)
    if path.exists() and not path.is_dir():
        raise OutputError(f"the output folder {os.fspath(path)} is a file, not a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        reason = err.strerror or str(err)
        raise OutputError(f"cannot create the output folder {os.fspath(path)}: {reason}") from None
    try:
        with tempfile.NamedTemporaryFile(dir=path, prefix=".uio-teach-write-test-"):
            pass
    except OSError as err:
        reason = err.strerror or str(err)
        raise OutputError(
            f"cannot write to the output folder {os.fspath(path)}: {reason}"
        ) from None
    return path


def sha256_file(path: str | os.PathLike[str]) -> str:
    """The SHA-256 of a file's bytes, as 64 hexadecimal digits.

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    str

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.folders import sha256_file
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     path = pathlib.Path(tmp) / "a.txt"
    ...     _ = path.write_bytes(b"abc")
    ...     sha256_file(path)[:16]
    'ba7816bf8f01cfea'
    """
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def library_versions() -> dict[str, str]:
    """The versions of Python, uio-teach and the libraries the figures depend on.

    Returns
    -------
    dict
        Name -> version (``"not installed"`` for a missing library).

    Examples
    --------
    >>> from uio_teach.folders import library_versions
    >>> sorted(library_versions())[:3]
    ['control', 'cvxpy', 'matplotlib']
    """
    versions = {"python": sys.version.split()[0], "uio-teach": __version__}
    for name in _LIBRARIES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = "not installed"
    return dict(sorted(versions.items()))


def _jsonable(value: Any) -> Any:
    if isinstance(value, complex):
        return value.real if value.imag == 0 else str(value).strip("()")
    if isinstance(value, (tuple, list)):
        return [_jsonable(v) for v in value]
    if isinstance(value, Mapping):
        return {str(k): _jsonable(v) for k, v in value.items()}
    return value


def write_manifest(
    folder: str | os.PathLike[str],
    *,
    command: str,
    config: Mapping[str, Any],
    options: Mapping[str, Any] | None = None,
) -> Path:
    """Write :data:`MANIFEST` into ``folder``: what was used and what was made.

    The manifest holds the command, the configuration as used (every key,
    defaults included) and the SHA-256 of its canonical JSON, the options
    (format, resolution, figures asked for), the versions of Python, uio-teach
    and the libraries, and every file of the folder and its sub-folders with
    its size and SHA-256 (names relative to ``folder``, with ``/``). It has
    no time stamp, so the same run gives the same manifest.

    Parameters
    ----------
    folder : str or path-like
        The folder the files were written into.
    command : str
        The command that made them, e.g. ``"uio-teach figures"``.
    config : mapping
        The configuration as used.
    options : mapping, optional
        Further settings of the run.

    Returns
    -------
    pathlib.Path
        The manifest's path.

    Examples
    --------
    >>> import json, tempfile, pathlib
    >>> from uio_teach.folders import write_manifest
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     _ = (pathlib.Path(tmp) / "a.csv").write_text("x\\n")
    ...     path = write_manifest(tmp, command="demo", config={"seed": 4})
    ...     data = json.loads(path.read_text())
    >>> [f["name"] for f in data["files"]], data["config"]
    (['a.csv'], {'seed': 4})
    """
    folder = Path(folder)
    cfg = _jsonable(dict(config))
    canonical = json.dumps(cfg, sort_keys=True, separators=(",", ":"))
    files = [
        {
            "name": p.relative_to(folder).as_posix(),
            "bytes": p.stat().st_size,
            "sha256": sha256_file(p),
        }
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p != folder / MANIFEST
    ]
    data = {
        "generator": "uio-teach",
        "command": command,
        "config": cfg,
        "config_sha256": hashlib.sha256(canonical.encode()).hexdigest(),
        "options": _jsonable(dict(options or {})),
        "versions": library_versions(),
        "files": files,
    }
    path = folder / MANIFEST
    path.write_text(json.dumps(data, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
    return path


def read_manifest(folder: str | os.PathLike[str]) -> dict[str, Any] | None:
    """The manifest of an earlier run in ``folder``, or ``None`` if it has none (or not ours).

    Parameters
    ----------
    folder : str or path-like
        The folder.

    Returns
    -------
    dict or None

    Examples
    --------
    >>> import tempfile
    >>> from uio_teach.folders import read_manifest
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     print(read_manifest(tmp))
    None
    """
    path = Path(folder) / MANIFEST
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or data.get("generator") != "uio-teach":
        return None
    return data


def _lock_nowait(fd: int) -> None:
    """Lock the open file ``fd`` for this process, or raise OSError at once if another holds it."""
    if sys.platform == "win32":  # pragma: no cover - the package is tested on Linux
        import msvcrt  # deferred on purpose: Windows only

        msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
    else:
        import fcntl  # deferred on purpose: POSIX only, so the package imports everywhere

        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)


class FolderLock:
    """Hold the lock of an output folder: one run at a time writes it.

    The lock is the file ``.<name>.lock`` beside the folder, locked with
    an advisory lock of the system (``flock`` on POSIX, ``msvcrt.locking`` on
    Windows) and holding the process id of its holder. The kernel
    releases the lock when its holder ends, however it ends, so the lock file
    of a killed run is simply taken over by the next one; a lock held by a
    live process is refused with :class:`OutputError` naming that process.

    Parameters
    ----------
    target : str or path-like
        The output folder (it need not exist).

    Raises
    ------
    OutputError
        The lock file cannot be made; :class:`FolderBusy` (an OutputError)
        when another process holds the lock.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.folders import FolderLock, OutputError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     target = pathlib.Path(tmp) / "labs"
    ...     with FolderLock(target):
    ...         try:
    ...             FolderLock(target).acquire()
    ...         except OutputError as err:
    ...             print("is writing" in str(err))
    True
    """

    def __init__(self, target: str | os.PathLike[str]) -> None:
        self.target = Path(os.path.abspath(target))
        self.path = self.target.parent / f".{self.target.name}.lock"
        self._fd: int | None = None

    def acquire(self) -> FolderLock:
        """Take the lock (never waits); returns ``self``."""
        try:
            self.target.parent.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise OutputError(
                f"cannot create the output folder {os.fspath(self.target)}: {err.strerror or err}"
            ) from None
        while True:
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o666)
            except OSError as err:
                raise OutputError(
                    f"cannot write beside the output folder {os.fspath(self.target)}: "
                    f"{err.strerror or err}"
                ) from None
            try:
                _lock_nowait(fd)
            except OSError:
                holder = os.read(fd, 32).decode("ascii", "replace").strip() or "?"
                os.close(fd)
                raise FolderBusy(
                    f"another uio-teach run (process {holder}) is writing "
                    f"{os.fspath(self.target)}; wait until it ends, or choose another folder"
                ) from None
            # the holder before us may have removed the file between our open and our lock
            try:
                same = os.path.samestat(os.fstat(fd), os.stat(self.path))
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        self._fd = fd
        return self

    def release(self) -> None:
        """Remove the lock file and let the lock go."""
        if self._fd is None:
            return
        try:
            os.unlink(self.path)
        except OSError:
            pass
        os.close(self._fd)  # closing releases the flock
        self._fd = None

    def __enter__(self) -> FolderLock:
        return self.acquire()

    def __exit__(self, *exc: object) -> None:
        self.release()


def _step() -> None:
    """One step of a staged run: a file written, or a point of the swap. It does nothing; the
    tests put a function of their own here to stop a run at a chosen step and look at what is
    left."""


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths in one atomic step (Linux ``renameat2``); False where it is not available."""
    if _RENAMEAT2 is None:
        return False
    res = _RENAMEAT2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    if res == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP):
        return False
    raise OSError(err, os.strerror(err), os.fspath(b))


def _find_renameat2() -> Any:
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        func = libc.renameat2
    except (OSError, AttributeError):
        return None
    func.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    func.restype = ctypes.c_int
    return func


_AT_FDCWD = -100
_RENAME_EXCHANGE = 2
_RENAMEAT2 = _find_renameat2() if sys.platform.startswith("linux") else None


class StagedFolder:
    """Write a folder all at once: into a staging folder beside it, swapped in by :meth:`commit`.

    This is the one way the instructor's commands write a folder (the
    figures, the lab notebooks, the graders' feedback). Use it as a context
    manager. Entering it

    1. takes the folder's :class:`FolderLock` (a second run into the same
       folder is refused, not raced);
    2. cleans what killed runs left beside the folder (staging folders
       ``.<name>.new-*`` and ``.<name>.old-*``; an earlier output that a
       run killed in the middle of a non-atomic swap left aside is put back);
    3. checks that the folder may be replaced (:func:`check_output_folder`);
    4. makes the staging folder :attr:`path`, with the user's usual
       permissions (the umask, not the private mode of a temporary folder).

    Write into :attr:`path` (calling :meth:`written` after each file lets a
    test stop the run there), then call :meth:`commit`. Leaving the block
    without a commit (a failure, an exception, Ctrl-C) deletes the staging
    folder and leaves ``target`` exactly as it was. A commit replaces
    ``target`` whole, in one atomic exchange of the two folders on Linux, so
    no file of an earlier run is left next to the new ones and a run killed at
    any point leaves the old set or the new set, never a mix.

    Parameters
    ----------
    target : str or path-like
        The folder to make or replace.
    what : str
        What goes in it, for messages (``"figures"``).
    command : str, optional
        The command writing it (``"uio-teach labs"``): an earlier output of
        another command is not replaced (see :func:`check_output_folder`).

    Raises
    ------
    OutputError
        ``target`` is a file; or it is a folder that is not empty and has no
        :data:`MANIFEST` of uio-teach (or of ``command``) (it does not look like an earlier output:
        empty it, or choose another folder); or another run is writing it; or
        the staging folder cannot be made beside it.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.folders import StagedFolder, write_manifest
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     target = pathlib.Path(tmp) / "figures"
    ...     with StagedFolder(target) as stage:
    ...         _ = (stage.path / "a.txt").write_text("new")
    ...         _ = write_manifest(stage.path, command="demo", config={})
    ...         print(target.exists())
    ...         _ = stage.commit()
    ...     print(sorted(p.name for p in target.iterdir()))
    False
    ['a.txt', 'manifest.json']
    """

    def __init__(
        self, target: str | os.PathLike[str], what: str = "output", command: str | None = None
    ) -> None:
        self.target = Path(target)
        self.what = what
        self.command = command
        self.committed = False
        self.path: Path | None = None
        self._lock = FolderLock(self.target)
        check_output_folder(self.target, self.command)

    def __enter__(self) -> StagedFolder:
        self._lock.acquire()
        try:
            clean_leftovers(self.target)
            check_output_folder(self.target, self.command)
            parent = self._lock.target.parent
            try:
                self.path = Path(tempfile.mkdtemp(dir=parent, prefix=f".{self.target.name}.new-"))
                os.chmod(self.path, 0o777 & ~_umask())
            except OSError as err:
                reason = err.strerror or str(err)
                raise OutputError(
                    f"cannot create the output folder {os.fspath(self.target)}: {reason}"
                ) from None
        except BaseException:
            self._lock.release()
            raise
        return self

    def written(self, path: str | os.PathLike[str] | None = None) -> None:
        """Note that one more file is in the staging folder (a point where a test may stop)."""
        _step()

    def commit(self) -> Path:
        """Swap the written folder in place of ``target``; returns ``target``."""
        assert self.path is not None, "use StagedFolder in a with block"
        check_output_folder(self.target, self.command)  # it may have changed while we were writing
        _step()
        target = self._lock.target
        if target.exists() and _exchange(self.path, target):
            # self.path now holds the earlier output
            self.committed = True
            _step()
            shutil.rmtree(self.path, ignore_errors=True)
            return self.target
        old = None
        if target.exists():
            old = Path(tempfile.mkdtemp(dir=target.parent, prefix=f".{target.name}.old-"))
            os.rmdir(old)
            os.replace(target, old)
            _step()
        try:
            os.replace(self.path, target)
        except OSError:
            if old is not None:
                os.replace(old, target)
            raise
        self.committed = True
        _step()
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        return self.target

    def __exit__(self, *exc: object) -> None:
        try:
            if not self.committed and self.path is not None:
                shutil.rmtree(self.path, ignore_errors=True)
        finally:
            self._lock.release()


def clean_leftovers(target: str | os.PathLike[str]) -> list[Path]:
    """Remove the staging folders that killed runs left beside ``target``.

    Call it only while holding the folder's :class:`FolderLock` (then no
    live run is using them). If ``target`` is missing but an earlier output
    was set aside (``.<name>.old-*``, a run killed between the two renames of
    a non-atomic swap), that output is put back first.

    Parameters
    ----------
    target : str or path-like
        The output folder.

    Returns
    -------
    list of pathlib.Path
        What was removed.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.folders import clean_leftovers
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     (pathlib.Path(tmp) / ".figs.new-abc").mkdir()
    ...     [p.name for p in clean_leftovers(pathlib.Path(tmp) / "figs")]
    ['.figs.new-abc']
    """
    target = Path(os.path.abspath(target))
    parent = target.parent
    if not parent.is_dir():
        return []
    aside = sorted(parent.glob(f".{glob.escape(target.name)}.old-*"))
    if not target.exists() and aside:
        restore = next((p for p in aside if read_manifest(p) is not None), None)
        if restore is not None:
            os.replace(restore, target)
            aside.remove(restore)
    removed = []
    for path in [*sorted(parent.glob(f".{glob.escape(target.name)}.new-*")), *aside]:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path, ignore_errors=True)
        else:
            path.unlink(missing_ok=True)
        removed.append(path)
    return removed


def check_output_folder(target: str | os.PathLike[str], command: str | None = None) -> None:
    """Raise :class:`OutputError` unless ``target`` may be made or replaced by a run.

    It may if it does not exist, is an empty folder, or holds an earlier
    output (a :data:`MANIFEST` of uio-teach; of ``command``, when given, so
    that the lab notebooks never replace the figures by mistake).

    Parameters
    ----------
    target : str or path-like
        The output folder.
    command : str, optional
        The command about to write it (``"uio-teach labs"``): an earlier
        output of another command is refused too.

    Raises
    ------
    OutputError
        ``target`` is a file, or a folder that is not empty and has no
        manifest of uio-teach (or of ``command``).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from uio_teach.folders import check_output_folder, OutputError
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     _ = (pathlib.Path(tmp) / "notes.txt").write_text("mine")
    ...     try:
    ...         check_output_folder(tmp)
    ...     except OutputError as err:
    ...         print("left alone" in str(err))
    True
    """
    target = Path(target)
    if target.exists() and not target.is_dir():
        raise OutputError(f"the output folder {os.fspath(target)} is a file, not a folder")
    if not target.is_dir() or not any(target.iterdir()):
        return
    manifest = read_manifest(target)
    if manifest is None:
        raise OutputError(
            f"the output folder {os.fspath(target)} is not empty and has no {MANIFEST} of "
            "uio-teach, so it does not look like an earlier output; it is left alone: empty "
            "it or choose another folder"
        )
    if command is not None and manifest.get("command") != command:
        raise OutputError(
            f"the output folder {os.fspath(target)} holds the output of "
            f"`{manifest.get('command')}`, not of `{command}`; it is left alone: choose "
            "another folder"
        )


def default_book_dir() -> Path:
    """The book's chapters: ``book/`` of a checkout, else the copy installed with the package.

    A wheel carries the chapters, ``_toc.yml`` and ``references.bib`` in
    ``uio_teach/_course/`` (``PACKAGED_COURSE``), so the labs can be
    written from any folder; ``./book`` is the last resort.

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> from uio_teach.folders import default_book_dir
    >>> default_book_dir().name
    'book'
    """
    checkout = Path(__file__).resolve().parents[1]
    for root in (checkout, PACKAGED_COURSE):
        if (root / "book").is_dir() and (root / "_toc.yml").is_file():
            return root / "book"
    return Path.cwd() / "book"
