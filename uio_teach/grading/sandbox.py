"""The sandbox a hand-in runs in: bubblewrap, with only its own folder visible.

:class:`Sandbox` turns a command into one run under ``bwrap`` (Debian package
``bubblewrap``) with

* its own mount namespace holding only: the read-only system folders
  (``/usr`` and the ``/bin``, ``/lib`` links, a few files of ``/etc``), the
  read-only Python installation, virtual environment and site folders, the
  package's code as a read-only copy of its modules alone
  (:func:`package_view`: no lab chapter, solution, answer key or notebook of
  the course, which a wheel carries in ``uio_teach/_course``; the installed
  package and the book's folder are hidden wherever a mounted folder holds
  them), and the hand-in's own work folder (writable, as ``/home/student``);
  a fresh ``/tmp`` in memory with a size cap, ``/dev`` and ``/proc``. The
  mounts are made parents first, so none hides another: an environment or
  a checkout under ``/tmp`` or ``/home`` is still there;
* its own process-id namespace (it sees no process of the grader; when the
  run ends, every process it started ends with it), network namespace (no
  network at all), IPC, UTS and user namespaces, and a new session (no
  terminal to write into);
* an emptied environment (only ``PATH``, ``HOME``, ``PYTHONPATH`` and the
  settings of matplotlib and Jupyter);
* resource limits (``setrlimit``, inherited by everything it starts): address
  space, number of processes, size of a written file, CPU time, no core dumps;
* when the grader runs as root, an unprivileged user id of its own
  (:class:`SandboxUser`, taken by :func:`drop_privileges` before any of the
  hand-in's code runs): root is exempt from the limit on processes, and the
  sandbox then holds no capability and no privilege on the host's files.
  The ids are dealt machine-wide: each is held, by a lock the kernel drops
  when its holder ends, in a folder of root's (:func:`uid_folder`), so two
  runs or shards on one machine, started in any order, never share one.

The total written into the work folder is capped by the runner
(:mod:`uio_teach.grading.runner`), which stops a run that exceeds it.
:func:`sandbox_problem` says why isolation is unavailable (no ``bwrap``, user
namespaces disabled, or the real interpreter cannot start or import the
package inside), or ``None``.

Examples
--------
>>> from uio_teach.grading.sandbox import Limits
>>> Limits().memory_mb
4096
"""

from __future__ import annotations

import atexit
import functools
import json
import os
import shutil
import stat
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import uio_teach

from ..errors import UIOTeachError

__all__ = [
    "Limits",
    "Sandbox",
    "SandboxUnavailable",
    "sandbox_problem",
    "SandboxUser",
    "uid_folder",
    "drop_privileges",
    "package_view",
    "hidden_paths",
    "BWRAP",
    "HOME",
    "TEMP_PREFIX",
    "UID_BASE",
    "UID_COUNT",
]

BWRAP = "bwrap"
"""The bubblewrap program (looked up on ``PATH``, then ``/usr/bin/bwrap``)."""
HOME = "/home/student"
"""Where the work folder appears inside the sandbox (also ``HOME`` and the working folder)."""
UID_BASE = 1_700_000_000
"""When the grader runs as root, each running hand-in runs as a user id of its own from
``UID_BASE`` on (:class:`SandboxUser`). These ids lie far above any login account, one per
running hand-in on the machine, so the limit on processes of one never counts another's."""
UID_COUNT = 1 << 20
"""The number of sandbox user ids, far more than hand-ins can run at once on a machine."""
_UID_FOLDERS = ("/run/uio-teach/sandbox-uids", "/var/tmp/uio-teach-sandbox-uids")
_PACKAGE_ROOT = "/opt/uio-teach"
TEMP_PREFIX = "uio-teach-grade-"
"""The name of every temporary folder of a grading run starts so (removed by the next run when
the run that made it was killed: see ``uio_teach.grading.grade.clean_leftovers``)."""
OWNER = "owner.json"
"""The file naming the process that owns a temporary folder (its pid and start time)."""
_ETC = (
    "/etc/ld.so.cache",
    "/etc/ld.so.conf",
    "/etc/ld.so.conf.d",
    "/etc/fonts",
    "/etc/passwd",
    "/etc/group",
    "/etc/nsswitch.conf",
    "/etc/localtime",
    "/etc/alternatives",
)


class SandboxUnavailable(UIOTeachError, RuntimeError):
    """Isolation is not available on this machine (one line saying why)."""


@dataclass(frozen=True)
class Limits:
    """The resource limits of one sandboxed run.

    Attributes
    ----------
    memory_mb : int
        Address space of each process (MiB).
    processes : int
        Processes and threads of the sandbox's user (``RLIMIT_NPROC``; a user
        of its own when the grader runs as root).
    file_mb : int
        Largest file a process may write (MiB).
    cpu_seconds : int
        CPU time of each process (a safety net under the wall-clock limit).
    tmp_mb : int
        Size of the sandbox's ``/tmp`` (in memory).
    disk_mb : int
        All a run may write into its work folder; the run is stopped beyond.
    output_mb : int
        All a run may print or display (text, figures, rich output); beyond,
        the output is cut and the row says so (its answers are graded).

    Examples
    --------
    >>> from uio_teach.grading.sandbox import Limits
    >>> Limits(memory_mb=2048).memory_mb, Limits().processes
    (2048, 256)
    """

    memory_mb: int = 4096
    processes: int = 256
    file_mb: int = 256
    cpu_seconds: int = 3600
    tmp_mb: int = 256
    disk_mb: int = 512
    output_mb: int = 32

    def apply(self) -> None:
        """Set the limits on the calling process; everything it starts inherits them.

        Soft and hard limits are set alike (CPU time keeps its hard limit, so
        the soft one ends the process with a signal), so the student's code
        cannot raise them again.
        """
        import resource  # deferred on purpose: POSIX only, so the package imports everywhere

        mib = 1024 * 1024
        for what, value in (
            (resource.RLIMIT_AS, self.memory_mb * mib),
            (resource.RLIMIT_NPROC, self.processes),
            (resource.RLIMIT_FSIZE, self.file_mb * mib),
            (resource.RLIMIT_CPU, self.cpu_seconds),
            (resource.RLIMIT_CORE, 0),
        ):
            _, hard = resource.getrlimit(what)
            if hard != resource.RLIM_INFINITY:
                value = min(value, hard)
            try:
                resource.setrlimit(what, (value, value if what != resource.RLIMIT_CPU else hard))
            except (ValueError, OSError):  # a limit this system does not allow lowering
                pass


def start_time(pid: int) -> str | None:
    """When the process ``pid`` started (clock ticks since boot), or None if it does not run."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[19]
    except (OSError, IndexError):
        return None


def own_folder(folder: Path) -> None:
    """Write :data:`OWNER` into ``folder``: this process owns it while it runs."""
    owner = {"pid": os.getpid(), "start": start_time(os.getpid())}
    (folder / OWNER).write_text(json.dumps(owner), encoding="utf-8")


@functools.lru_cache(maxsize=1)
def package_view() -> str:
    """A read-only copy of the package's modules alone, for the sandbox to import.

    Only the ``*.py`` files of ``uio_teach`` (and their compiled copies) are
    copied (once per process, into a temporary folder removed at exit): no lab
    chapter, no book, nothing else an installed package may carry. Readable by
    every user (a grader running as root runs each hand-in as a user of its own).

    Returns
    -------
    str
        The copy's ``uio_teach`` folder.
    """
    package = Path(uio_teach.__file__).resolve().parent
    root = Path(tempfile.mkdtemp(prefix=f"{TEMP_PREFIX}package-"))
    own_folder(root)
    view = root / "uio_teach"
    tag = sys.implementation.cache_tag or ""
    for source in sorted(package.rglob("*.py")):
        relative = source.relative_to(package)
        if relative.parts[0].startswith("_course") or "__pycache__" in relative.parts:
            continue
        target = view / relative
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, target)  # its time kept: the compiled copy below stays valid
        compiled = source.parent / "__pycache__" / f"{source.stem}.{tag}.pyc"
        if tag and compiled.is_file():  # imports in the sandbox need not compile every module
            (target.parent / "__pycache__").mkdir(exist_ok=True)
            shutil.copy2(compiled, target.parent / "__pycache__" / compiled.name)
    for path in [root, *root.rglob("*")]:
        path.chmod(0o755 if path.is_dir() else 0o644)
    atexit.register(shutil.rmtree, root, True)
    return os.fspath(view)


def hidden_paths() -> list[Path]:
    """What the sandbox hides wherever a mounted folder holds it: the package as installed
    (its modules are seen through :func:`package_view` instead) and the book's chapters.

    Returns
    -------
    list of pathlib.Path
    """
    package = Path(uio_teach.__file__).resolve().parent
    hidden = [package]
    checkout = package.parent
    if (checkout / "_toc.yml").is_file() or (checkout / "book").is_dir():
        hidden.append(checkout / "book")  # a checkout: its chapters, solutions included
    return hidden


def _masks(mounted: Sequence[tuple[str, str, str]]) -> list[tuple[str, str, str]]:
    """Mounts that hide :func:`hidden_paths` inside the read-only folders mounted as they are."""
    view = package_view()
    package = Path(uio_teach.__file__).resolve().parent
    out: list[tuple[str, str, str]] = []
    for kind, source, dest in mounted:
        if kind not in ("--ro-bind", "--ro-bind-try") or not source:
            continue
        root = Path(source).resolve()
        for secret in hidden_paths():
            if secret == root or root not in secret.parents or not secret.exists():
                continue
            where = os.fspath(Path(dest) / secret.relative_to(root))
            if secret == package:
                out.append(("--ro-bind", view, where))
            else:
                out.append(("--tmpfs", "", where))
    return out


def _site_folders() -> list[str]:
    """The site folders on the grader's ``sys.path`` (a ``.pth`` may add one outside the
    environment): mounted so the sandbox imports what the grader imports, and nothing else."""
    found = []
    for entry in sys.path:
        path = Path(entry or ".")
        if path.name in ("site-packages", "dist-packages") and path.is_dir():
            found.append(os.fspath(path.resolve()))
    return found


def _bwrap() -> str | None:
    return shutil.which(BWRAP) or (
        "/usr/bin/bwrap" if os.access("/usr/bin/bwrap", os.X_OK) else None
    )


@functools.lru_cache(maxsize=1)
def _bwrap_has_size() -> bool:
    """Whether this bubblewrap caps a tmpfs (``--size``, bubblewrap 0.8 and later)."""
    program = _bwrap()
    try:
        done = subprocess.run([program or BWRAP, "--help"], capture_output=True, text=True)
    except OSError:
        return False
    return "--size" in done.stdout + done.stderr


def uid_folder() -> Path:
    """The folder of root's where the sandbox user ids in use are held (made on first use).

    ``/run/uio-teach/sandbox-uids`` (gone at the next boot), else
    ``/var/tmp/uio-teach-sandbox-uids``: machine-wide, so every grading run of
    the machine, whatever its folder or its shard, deals from the same ids.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    SandboxUnavailable
        Neither can be made, or one exists that is not a folder of root's alone
        (a link, or writable by others): it is not used.
    """
    problems = []
    for name in _UID_FOLDERS:
        folder = Path(name)
        try:
            folder.mkdir(mode=0o700, parents=True, exist_ok=True)
            info = os.lstat(folder)
        except OSError as err:
            problems.append(f"{name}: {err.strerror or err}")
            continue
        if not stat.S_ISDIR(info.st_mode) or info.st_uid != 0 or info.st_mode & 0o022:
            problems.append(f"{name} is not a folder of root's alone")
            continue
        return folder
    raise SandboxUnavailable("no folder to hold the sandbox user ids in: " + "; ".join(problems))


def _uid_running(uid: int) -> bool:
    """Whether any process of the machine runs with the real user id ``uid``."""
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            with open(f"/proc/{entry.name}/status", encoding="ascii", errors="replace") as fh:
                for line in fh:
                    if line.startswith("Uid:"):
                        if int(line.split()[1]) == uid:
                            return True
                        break
        except (OSError, ValueError, IndexError):
            continue
    return False


class SandboxUser:
    """The user id one sandboxed run takes, unique on the machine while it is held.

    When the grader runs as root, :meth:`acquire` takes the lowest id from
    :data:`UID_BASE` whose lock file in :func:`uid_folder` no other process
    holds (an advisory ``flock``, which the kernel drops when its holder
    ends, however it ends) and that no process of the machine runs as (what a
    killed run may have left). Every grading run and shard on the machine
    deals from the same ids, so a hand-in holding processes in one run never
    counts against the limit of processes of a hand-in in another. When the
    grader is not root, the run keeps the grader's own user (:attr:`uid` is
    None) and nothing is held.

    Examples
    --------
    >>> import os
    >>> from uio_teach.grading.sandbox import UID_BASE, SandboxUser
    >>> with SandboxUser() as uid, SandboxUser() as other:
    ...     print(uid is None if os.geteuid() else UID_BASE <= uid != other)
    True
    """

    def __init__(self) -> None:
        self.uid: int | None = None
        self._fd: int | None = None

    def acquire(self) -> int | None:
        """Take a free id (the grader as root) or none; returns :attr:`uid`."""
        if not hasattr(os, "geteuid") or os.geteuid() != 0:
            return None
        import fcntl  # deferred on purpose: POSIX only, so the package imports everywhere

        folder = uid_folder()
        for uid in range(UID_BASE, UID_BASE + UID_COUNT):
            fd = os.open(folder / str(uid), os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o600)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                os.close(fd)
                continue
            if _uid_running(uid):  # left by a run that was killed: not dealt again while it runs
                os.close(fd)
                continue
            self.uid, self._fd = uid, fd
            return uid
        raise SandboxUnavailable(f"all {UID_COUNT} sandbox user ids are in use")

    def release(self) -> None:
        """Let the id go (once every process of its run has ended)."""
        if self._fd is not None:
            os.close(self._fd)  # closing drops the flock
        self.uid, self._fd = None, None

    def __enter__(self) -> int | None:
        return self.acquire()

    def __exit__(self, *exc: object) -> None:
        self.release()


def _probe_command(user: int | None) -> list[str]:
    """The real interpreter, importing the package and the notebook runner, as a hand-in would."""
    code = (
        "from uio_teach.grading.sandbox import drop_privileges; "
        f"drop_privileges({user!r}); "
        "import uio_teach, nbclient, ipykernel, numpy; "
        "open('/tmp/probe', 'w').write('x'); open('probe', 'w').write('x'); "
        "print('uio-teach sandbox ok')"
    )
    return [sys.executable, "-c", code]


@functools.lru_cache(maxsize=1)
def _problem() -> str | None:
    if not sys.platform.startswith("linux"):
        return "the sandbox needs Linux namespaces (bubblewrap); this system is not Linux"
    program = _bwrap()
    if program is None:
        return (
            "bubblewrap (bwrap) is not installed: install it (Debian/Ubuntu: "
            "apt-get install bubblewrap)"
        )
    import tempfile  # deferred on purpose: only the probe needs a folder

    with tempfile.TemporaryDirectory(prefix="uio-teach-probe-") as tmp, SandboxUser() as user:
        work = Path(tmp) / "work"
        work.mkdir()
        if user is not None:
            os.chown(work, user, user)
        sandbox = Sandbox(work, user=user)
        try:
            proc = sandbox.popen(
                _probe_command(user), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
            )
        except OSError as err:
            return f"bubblewrap cannot run: {err}"
        try:
            stdout, stderr = proc.communicate(timeout=120)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
            return "bubblewrap did not start Python within 120 s"
        done = subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr)
    if done.returncode == 0 and "uio-teach sandbox ok" in done.stdout:
        return None
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    why = lines[-1].strip() if lines else f"exit status {done.returncode}"
    if why.startswith("bwrap:") and ("namespace" in why or "Operation not permitted" in why):
        return (
            f"bubblewrap cannot create the namespaces ({why}); user namespaces may be "
            "disabled (sysctl kernel.unprivileged_userns_clone) or forbidden in this container"
        )
    return (
        f"the interpreter {sys.executable} cannot run inside the sandbox with the package "
        f"{Path(uio_teach.__file__).parent} ({why[:300]}); when grading as root, they must "
        "be readable by every user"
    )


def sandbox_problem() -> str | None:
    """Why hand-ins cannot be isolated here, or ``None`` when they can.

    The probe runs the real interpreter inside the sandbox, as a hand-in
    runs (as an unprivileged user when the grader is root): it starts
    Python, imports the package, the notebook runner and NumPy, and writes
    into its ``/tmp``. The answer is kept for the life of the process.

    Returns
    -------
    str or None

    Examples
    --------
    >>> from uio_teach.grading.sandbox import sandbox_problem
    >>> sandbox_problem() is None or isinstance(sandbox_problem(), str)
    True
    """
    try:
        return _problem()
    except SandboxUnavailable as err:
        return str(err)


def _open_parents(mounts: Sequence[tuple[str, str, str]]) -> list[str]:
    """``--chmod 0755`` for every folder bwrap creates above a mount (not inside one)."""
    every = [Path(dest) for kind, _, dest in mounts if kind != "--symlink"]
    # a folder made inside a bound host folder is the host's (read-only); one made inside the
    # sandbox's own /tmp or root is bwrap's, root's and closed: opened here
    bound = [Path(d) for kind, _, d in mounts if kind in ("--bind", "--ro-bind", "--ro-bind-try")]
    made: list[str] = []
    for dest in every:
        for parent in list(dest.parents)[::-1][1:]:  # "/" left out, outermost first
            inside = any(parent == b or b in parent.parents for b in bound)
            if not inside and os.fspath(parent) not in made:
                made.append(os.fspath(parent))
    return [arg for path in made for arg in ("--chmod", "0755", path)]


class Sandbox:
    """Run commands under bubblewrap with only ``work`` visible (writable) and read-only Python.

    Parameters
    ----------
    work : path
        The hand-in's work folder: the only writable place on disk, seen
        inside as :data:`HOME`.
    limits : Limits, optional
        Only its ``tmp_mb`` is used here (the size of ``/tmp``).
    user : int, optional
        The user id to run as (:class:`SandboxUser`); None keeps yours.

    Examples
    --------
    >>> from pathlib import Path
    >>> from uio_teach.grading.sandbox import Sandbox
    >>> cmd = Sandbox(Path("/tmp/x")).wrap(["python3", "-c", "pass"])
    >>> "--unshare-net" in cmd and "--unshare-pid" in cmd
    True
    >>> cmd.index("/tmp") < cmd.index("/home/student")  # parents first: nothing hidden
    True
    """

    def __init__(self, work: Path, *, limits: Limits | None = None, user: int | None = None):
        self.work = Path(work)
        self.limits = limits or Limits()
        self.user = user

    def _mounts(self) -> list[tuple[str, str, str]]:
        """Every mount as (kind, source, destination), parents before children."""
        mounts: list[tuple[str, str, str]] = [("--ro-bind", "/usr", "/usr")]
        for name in ("bin", "lib", "lib32", "lib64", "sbin"):
            path = Path("/") / name
            if path.is_symlink():
                mounts.append(("--symlink", os.readlink(path), f"/{name}"))
            elif path.is_dir():
                mounts.append(("--ro-bind", f"/{name}", f"/{name}"))
        for path in _ETC:
            mounts.append(("--ro-bind-try", path, path))
        mounted = {"/usr"}
        for prefix in sorted({sys.base_prefix, sys.prefix, sys.exec_prefix, *_site_folders()}):
            inside = any(prefix == m or prefix.startswith(m.rstrip("/") + "/") for m in mounted)
            if not inside:
                mounts.append(("--ro-bind", prefix, prefix))
                mounted.add(prefix)
        mounts += _masks(mounts)
        mounts.append(("--ro-bind", package_view(), f"{_PACKAGE_ROOT}/uio_teach"))
        mounts += [
            ("--proc", "", "/proc"),
            ("--dev", "", "/dev"),
            ("--tmpfs", "", "/tmp"),
            ("--bind", os.fspath(self.work), HOME),
        ]
        # parents first: a tmpfs on /tmp made after the environment would hide an environment
        # that lives under /tmp; sorted by depth, every mount is made on top of its parents
        mounts.sort(key=lambda m: len(Path(m[2]).parts))
        return mounts

    def wrap(self, command: Sequence[str]) -> list[str]:
        """The bwrap command line that runs ``command`` inside the sandbox.

        Parameters
        ----------
        command : sequence of str
            The program and its arguments (paths as seen inside).

        Returns
        -------
        list of str
        """
        args = [_bwrap() or BWRAP]
        if self.user is None:  # a user namespace of its own
            args += ["--unshare-user-try"]
        else:  # root: only the right to become the unprivileged `user` (on the host), then none
            args += ["--cap-drop", "ALL", "--cap-add", "CAP_SETUID", "--cap-add", "CAP_SETGID"]
        args += ["--unshare-ipc", "--unshare-pid", "--unshare-net", "--unshare-uts"]
        args += ["--unshare-cgroup-try", "--die-with-parent", "--new-session"]
        for kind, source, dest in self._mounts():
            if kind in ("--proc", "--dev"):
                args += [kind, dest]
            elif kind == "--tmpfs":
                if _bwrap_has_size():
                    args += ["--size", str(self.limits.tmp_mb * 1024 * 1024)]
                args += [kind, dest]
            elif kind == "--symlink":
                args += [kind, source, dest]
            else:
                args += [kind, source, dest]
        if self.user is not None:  # the folders bwrap made on the way are root's: open them
            args += [*_open_parents(self._mounts()), "--chmod", "1777", "/tmp"]
        args += ["--chdir", HOME, "--clearenv"]
        env = {
            "PATH": f"{Path(sys.executable).parent}:/usr/local/bin:/usr/bin:/bin",
            "HOME": HOME,
            "USER": "student",
            "LOGNAME": "student",
            "PYTHONPATH": _PACKAGE_ROOT,
            "PYTHONHASHSEED": "0",
            "PYTHONDONTWRITEBYTECODE": "1",
            "MPLBACKEND": "Agg",
            "MPLCONFIGDIR": f"{HOME}/.config/matplotlib",
            "JUPYTER_RUNTIME_DIR": "/tmp/jupyter",
            "JUPYTER_PLATFORM_DIRS": "1",
            "TMPDIR": "/tmp",
            "OMP_NUM_THREADS": "1",
            "OPENBLAS_NUM_THREADS": "1",
            "LANG": "C.UTF-8",
        }
        for key, value in env.items():
            args += ["--setenv", key, value]
        return [*args, "--", *command]

    def popen(self, command: Sequence[str], **kwargs) -> subprocess.Popen:
        """Start ``command`` in the sandbox, in a new session of its own.

        The limits are applied by the command itself (the grading runner calls
        :func:`drop_privileges` and :meth:`Limits.apply` first thing), not
        here: ``preexec_fn`` is unsafe with the grader's threads.

        Parameters
        ----------
        command : sequence of str
        **kwargs
            Passed to :class:`subprocess.Popen` (not ``preexec_fn``).

        Returns
        -------
        subprocess.Popen
        """
        return subprocess.Popen(self.wrap(command), start_new_session=True, **kwargs)


def drop_privileges(user: int | None) -> None:
    """Become the unprivileged ``user`` for good (the first act inside a root grader's sandbox).

    Inside the sandbox of a grader running as root, the process starts as
    root with only the capabilities to change its user; it then takes the
    user id ``user`` (group alike, no supplementary groups), which leaves it
    no capability at all, and bubblewrap's *no new privileges* keeps
    set-user-id programs from giving any back.

    Parameters
    ----------
    user : int or None
        None does nothing (the grader is not root: the sandbox already runs as its user).

    Raises
    ------
    PermissionError
        The user could not be taken, or the process still holds a capability.
    """
    if user is None:
        return
    os.setgroups([])
    os.setgid(user)
    os.setuid(user)
    status = Path("/proc/self/status").read_text()
    held = [line for line in status.splitlines() if line.startswith(("CapEff", "CapPrm"))]
    if os.getuid() != user or any(int(line.split()[1], 16) for line in held):
        raise PermissionError(f"could not drop to the unprivileged user {user}")
