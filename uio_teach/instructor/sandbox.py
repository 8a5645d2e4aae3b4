"""The sandbox a submission runs in: bubblewrap, with only its own folder visible.

:class:`Sandbox` turns a command into one run under ``bwrap`` (Debian package
``bubblewrap``) with

* its own mount namespace holding only: the read-only system folders
  (``/usr`` and the ``/bin``, ``/lib`` links, a few files of ``/etc``), the
  read-only Python installation and virtual environment, the read-only
  ``uio_teach`` package, and the submission's own work folder (writable, as
  ``/home/student``); a fresh ``/tmp`` (in memory), ``/dev`` and ``/proc``;
* its own process-id namespace (it sees no process of the grader; when the
  run ends, every process it started ends with it), network namespace (no
  network at all), IPC, UTS and user namespaces, and a new session (no
  terminal to write into);
* an emptied environment (only ``PATH``, ``HOME``, ``PYTHONPATH`` and the
  settings of matplotlib and Jupyter);
* resource limits (``setrlimit``, inherited by everything it starts): address
  space, number of processes, size of a written file, CPU time, no core dumps.

:func:`sandbox_problem` says why isolation is unavailable (no ``bwrap``, or
user namespaces disabled), or ``None``.

Examples
--------
>>> from uio_teach.instructor.sandbox import Limits
>>> Limits().memory_mb
4096
"""

from __future__ import annotations

import functools
import os
import resource
import shutil
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import uio_teach

from ..errors import UIOTeachError

__all__ = ["Limits", "Sandbox", "SandboxUnavailable", "sandbox_problem", "BWRAP", "HOME"]

BWRAP = "bwrap"
"""The bubblewrap program (looked up on ``PATH``, then ``/usr/bin/bwrap``)."""
HOME = "/home/student"
"""Where the work folder appears inside the sandbox (also ``HOME`` and the working folder)."""
_PACKAGE_ROOT = "/opt/uio-teach"
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
        Processes and threads of the user (``RLIMIT_NPROC``).
    file_mb : int
        Largest file a process may write (MiB).
    cpu_seconds : int
        CPU time of each process (a safety net under the wall-clock limit).

    Examples
    --------
    >>> from uio_teach.instructor.sandbox import Limits
    >>> Limits(memory_mb=2048).memory_mb, Limits().processes
    (2048, 1024)
    """

    memory_mb: int = 4096
    processes: int = 1024
    file_mb: int = 256
    cpu_seconds: int = 3600

    def apply(self) -> None:
        """Set the limits on the calling process; everything it starts inherits them.

        Soft and hard limits are set alike (CPU time keeps its hard limit, so
        the soft one ends the process with a signal), so the student's code
        cannot raise them again.
        """
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


def _bwrap() -> str | None:
    return shutil.which(BWRAP) or (
        "/usr/bin/bwrap" if os.access("/usr/bin/bwrap", os.X_OK) else None
    )


@functools.lru_cache(maxsize=1)
def sandbox_problem() -> str | None:
    """Why submissions cannot be isolated here, or ``None`` when they can.

    Returns
    -------
    str or None

    Examples
    --------
    >>> from uio_teach.instructor.sandbox import sandbox_problem
    >>> sandbox_problem() is None or isinstance(sandbox_problem(), str)
    True
    """
    if not sys.platform.startswith("linux"):
        return "the sandbox needs Linux namespaces (bubblewrap); this system is not Linux"
    program = _bwrap()
    if program is None:
        return (
            "bubblewrap (bwrap) is not installed: install it (Debian/Ubuntu: "
            "apt-get install bubblewrap)"
        )
    probe = Sandbox(Path("/")).wrap(["/bin/true"], bind_work=False)
    try:
        done = subprocess.run(probe, capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as err:
        return f"bubblewrap cannot run: {err}"
    if done.returncode != 0:
        lines = [line for line in done.stderr.splitlines() if line.strip()]
        why = lines[-1] if lines else f"exit status {done.returncode}"
        return (
            f"bubblewrap cannot create the namespaces ({why}); user namespaces may be "
            "disabled (sysctl kernel.unprivileged_userns_clone) or forbidden in this container"
        )
    return None


class Sandbox:
    """Run commands under bubblewrap with only ``work`` visible (writable) and read-only Python.

    Parameters
    ----------
    work : path
        The submission's work folder: the only writable place, seen inside as
        :data:`HOME`.

    Examples
    --------
    >>> from pathlib import Path
    >>> from uio_teach.instructor.sandbox import Sandbox
    >>> cmd = Sandbox(Path("/tmp/x")).wrap(["python3", "-c", "pass"])
    >>> "--unshare-net" in cmd and "--unshare-pid" in cmd
    True
    """

    def __init__(self, work: Path) -> None:
        self.work = Path(work)

    def wrap(self, command: Sequence[str], *, bind_work: bool = True) -> list[str]:
        """The bwrap command line that runs ``command`` inside the sandbox.

        Parameters
        ----------
        command : sequence of str
            The program and its arguments (paths as seen inside).
        bind_work : bool
            Mount the work folder (False for a probe).

        Returns
        -------
        list of str
        """
        args = [_bwrap() or BWRAP, "--unshare-user-try", "--unshare-ipc", "--unshare-pid"]
        args += ["--unshare-net", "--unshare-uts", "--unshare-cgroup-try"]
        args += ["--die-with-parent", "--new-session"]
        args += ["--ro-bind", "/usr", "/usr"]
        for name in ("bin", "lib", "lib32", "lib64", "sbin"):
            path = Path("/") / name
            if path.is_symlink():
                args += ["--symlink", os.readlink(path), f"/{name}"]
            elif path.is_dir():
                args += ["--ro-bind", f"/{name}", f"/{name}"]
        for path in _ETC:
            args += ["--ro-bind-try", path, path]
        for prefix in sorted({sys.base_prefix, sys.prefix, sys.exec_prefix}):
            if not prefix.startswith("/usr"):
                args += ["--ro-bind", prefix, prefix]
        package = Path(uio_teach.__file__).resolve().parent
        args += ["--ro-bind", os.fspath(package), f"{_PACKAGE_ROOT}/uio_teach"]
        args += ["--proc", "/proc", "--dev", "/dev", "--tmpfs", "/tmp"]
        if bind_work:
            args += ["--bind", os.fspath(self.work), HOME, "--chdir", HOME]
        args += ["--clearenv"]
        env = {
            "PATH": f"{Path(sys.executable).parent}:/usr/local/bin:/usr/bin:/bin",
            "HOME": HOME if bind_work else "/tmp",
            "PYTHONPATH": _PACKAGE_ROOT,
            "PYTHONHASHSEED": "0",
            "MPLBACKEND": "Agg",
            "MPLCONFIGDIR": f"{HOME}/.config/matplotlib" if bind_work else "/tmp",
            "JUPYTER_RUNTIME_DIR": "/tmp/jupyter",
            "JUPYTER_PLATFORM_DIRS": "1",
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
        :meth:`Limits.apply` first thing), not here: ``preexec_fn`` is unsafe
        with the grader's threads.

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
