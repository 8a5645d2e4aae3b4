"""The instructor's command line: ``uio-teach figures``, ``uio-teach labs`` and ``uio-teach grade``.

Run it as ``python -m uio_teach ...`` or, once the package is installed, as
``uio-teach ...``. :func:`main` takes the arguments as a list and returns the
exit status, so it can also be called from Python (and from tests):

* 0: everything was written;
* 1: something could not be made or written (one line on stderr says what);
* 2: a usage or configuration error (one line on stderr names the option or
  key).

Examples
--------
>>> from uio_teach.instructor.cli import main
>>> main(["figures", "--list"])  # doctest: +ELLIPSIS
pa9_sine ...
0
>>> main(["figures", "--only", "pa9_sin", "--out", "unused"])  # doctest: +ELLIPSIS
2
"""

from __future__ import annotations

import argparse
import os
import sys
import textwrap
import time
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NoReturn, TextIO

import matplotlib

from .. import __version__
from ..folders import MANIFEST, OutputError, check_output_folder
from .config import DPI_RANGE, ConfigError, FigureConfig, check_dpi, load_config
from .output import FORMATS

# Each command imports the module that does its work only when it runs (figures draws with
# matplotlib, grade starts kernels): deferred on purpose, so `uio-teach --help` and a usage
# error answer at once.

__all__ = ["main", "build_parser"]

PROG = "uio-teach"

_MAIN_DESCRIPTION = """\
Instructor tools of the course "Unknown Input Observers".

Four commands:
  figures   regenerate every figure of the course (and Table II of the missile paper)
  labs      write the lab notebooks, a student version and a solution version
  grade     run the notebooks the groups handed in and write a gradebook (CSV)
  merge     merge the gradebooks of a class graded in shards (grade --shard K/N)

Run `uio-teach COMMAND --help` for the options of each command.
"""

_MAIN_EPILOG = """\
examples:
  uio-teach figures --out handout/figures
  uio-teach figures --out handout/figures --config term.toml --format pdf
  uio-teach labs --out handout/labs
  uio-teach grade submissions/*.ipynb --out grades.csv

exit status:
  0 everything was written, 1 something could not be made or written,
  2 a usage or configuration error.
"""

_FIGURES_DESCRIPTION = """\
Regenerate the figures of the course into one folder:

  * Practical Assignment 9: the error and the residual of the decoupling
    observer under a sinusoidal and under a piecewise-constant disturbance,
    the states with their estimates, and the contrast with a Luenberger
    observer that has the same poles;
  * the discrete-time case study: states, estimates, error and residual with
    both unknown signals active, and the error norm on a log scale;
  * the missile autopilot: the estimates of the projection-operator observer
    (PMO) and of the g-inverse observer, their errors, the reconstructed
    unknown inputs v1 and v2, and Table II (catch times within 2 % of the
    signal's peak, next to the paper's) as missile_table2.csv and .md.

The files are named after the figures (`--list`), e.g. DIR/pa9_sine.png,
with DIR/manifest.json (the configuration as used and its hash, the versions,
each file's SHA-256). The same command gives byte-identical files: the noise
is seeded and no time stamp is written into PNG, PDF or SVG files.

All or nothing: the files are written into a temporary folder beside DIR,
which replaces DIR only when every figure was made. A failed or interrupted
run leaves DIR as it was; a good run leaves only its own files (with --only,
just those figures). DIR is replaced only if it is empty or holds earlier
figures (their manifest.json); any other folder is left alone (exit status 1), and
so is a folder that another run is writing (a lock beside it, .DIR.lock).
Staging folders left by a killed run (.DIR.new-*) are removed by the next run.

The parameters that change from one term to the next (disturbances, observer
poles, noise level, seed, matplotlib style) are read from a TOML file given
with --config; every key is optional. `--print-config` prints all the keys
with their defaults and a comment each: save it as a starting point.
"""

_FIGURES_EPILOG = """\
examples:
  uio-teach figures --list
  uio-teach figures --out figures
  uio-teach figures --out figures --only pa9_sine pa9_piecewise --format svg
  uio-teach figures --print-config > term.toml     # edit, then:
  uio-teach figures --out figures --config term.toml --dpi 200

a configuration file (term.toml):
  seed = 7
  [pa9]
  poles = [-2.0, -3.0, -4.0]        # complex poles as strings: "-1+1j", "-1-1j"
  [pa9.sine]
  amplitude = 0.5
  frequency = 3.0                   # rad/s
  [pa9.piecewise]
  times = [0.0, 3.0, 6.0]
  values = [1.0, -2.0, 0.5]

exit status:
  0 all figures written, 1 a figure or the output folder failed (nothing
  written), 2 a usage or configuration error (unknown key, wrong type, a value
  out of its range, wrong pole count, unstable pole), one line per problem.
"""

_LABS_DESCRIPTION = """\
Write every lab of the book (book/*lab*.md, MyST notebooks) as two Jupyter
notebooks, with empty outputs:

  DIR/student/<lab>.ipynb   each solution replaced by a cell starting with
                            `# TODO: Exercise <number> (<label>)`; check cells
                            kept, the instructor notes left out
  DIR/solution/<lab>.ipynb  complete, for marking: solution cells tagged
                            `solution`, check cells tagged `check`

In the student version a TODO cell sets the names that the later check cells
use to None, so the notebook runs from top to bottom and each check says what
is still missing; a question answered in words gets a "Your answer" cell.

The numbers of each lab (poles, disturbances, switching times, noise, seeds)
are in its cell tagged `parameters` (`PARAMS = {...}`); the code and the checks
read them from there. --config takes them from the term config (the keys of
`uio-teach figures --print-config`), style included. These keys go into PARAMS
but the notebooks do not read them:
{unread}

--groups N --seed S draws numbers of its own for every group, each a fair
exercise (the observer exists, poles distinct and stable, disturbances
visible), and writes

  DIR/<lab>/student/<lab>_g01.ipynb, DIR/<lab>/solution/<lab>_g01.ipynb, ...
  DIR/answer_key.csv        one row per lab and group: lab, group, params,
                            then the expected matrices and numbers (JSON)

The same seed gives byte-identical files. DIR/manifest.json lists what was
written (the configuration as used and its hash, the options, the versions,
each file's SHA-256).

All or nothing, as for figures: the notebooks are written into a temporary
folder beside DIR, which replaces DIR whole only when every file is written,
so a rerun (--groups 3, then --groups 2) leaves no notebook of the earlier run
and a failed or killed run leaves DIR as it was. DIR is replaced only if it is
empty or holds earlier lab notebooks (their manifest.json); any other folder is
left alone (exit status 1), and so is a folder another run is writing.
"""

_LABS_EPILOG = """\
examples:
  uio-teach labs --out handout/labs
  uio-teach labs --out handout/labs --source book/lab_pa9.md
  uio-teach labs --out handout/labs --config term.toml
  uio-teach labs --out handout/labs --groups 12 --seed 2026

exit status:
  0 all notebooks written, 1 a lab could not be read or written (nothing
  written), 2 a usage or configuration error, one line per problem.
"""


_GRADE_DESCRIPTION = """\
Grade the lab notebooks the groups handed in (a folder, or the files). Each
one is run on a copy (the hand-in is only read), in a fresh kernel inside a
sandbox (bubblewrap: only its own copy visible, no network, no other process,
limits on memory, processes, writes and time), with its stored outputs
cleared. Its answer variables are then taken out as data and checked in a
separate process under limits of time and memory, with the group's parameters
from --groups-from. The group comes from the file name (pa9_g03.ipynb) or
from --roster, never from the notebook: when the notebook's metadata
disagrees, a group hands in twice, or two groups hand in the same code, the
row says "check by hand". The verdicts the notebook prints count for nothing.

Every hand-in gets its row, whatever happens to it: links, folders and
devices are refused, a file that is not a notebook is unreadable, answers
over the size caps are "over limits"; the run goes on and says at the end
how many rows need a look. A hand-in is any entry named *.ipynb (any case) of
the folder, at any depth (an LMS's download in folders); every other entry
(an archive, a script, a folder) gets a line saying why it is not graded,
and what appears during the run is listed as not graded.

Writes FILE (one row per hand-in: file, lab, group, status, reason, one
column per check with ✓ or ✗, total, out_of and late), FILE's stem + _feedback/
(a text and an HTML page per hand-in), FILE's stem + _groups.csv (one row per
group), + _canvas.csv (Canvas's gradebook import, with its "Points
Possible" row) and + _moodle.csv (Moodle's grade import, by ID number); the
last two only with a --roster naming the students, since without one no row
could be matched to a student. Each row is written as soon as its
hand-in is graded; --resume grades only the missing ones; Ctrl-C stops at
once and keeps them.

A large class can be split over machines: --shard K/N grades shard K of N
(each hand-in in exactly one shard, by its file name), and `uio-teach merge`
puts the N gradebooks together into what one whole run writes.

GRADING RUNS THE STUDENTS' CODE. Without bubblewrap (apt-get install
bubblewrap) grading is refused; --no-sandbox runs the code with your
permissions (it can read the answer key and delete what you can).
"""

_GRADE_EPILOG = """\
examples:
  uio-teach grade handed_in --out grades.csv
  uio-teach grade handed_in --out grades.csv --groups-from labs/answer_key.csv
  uio-teach grade handed_in --out grades.csv --roster groups.csv
  uio-teach grade handed_in/*.ipynb --out grades.csv --timeout 600 --cell-timeout 120
  uio-teach grade handed_in --out grades.csv --jobs 2 --resume
  uio-teach grade handed_in --out grades_2.csv --shard 2/4   # then uio-teach merge

exit status:
  0 every hand-in has its row (whatever its grade or status), 1 the gradebook
  could not be written, 2 a usage error (no such hand-in folder or file, an
  unreadable answer key or roster, no working sandbox), 130 interrupted.
"""


_MERGE_DESCRIPTION = """\
Merge the gradebooks of a class graded in shards (`uio-teach grade ...
--shard K/N` for K = 1..N, on one machine or several) into FILE: every row
in the class's order, the feedback texts and pages, the per-group and Canvas
exports and the manifest, exactly as one whole run writes them. Refused,
naming the gradebooks: shards of different classes, answer keys or rosters,
a shard given twice or missing, a hand-in with a row in two gradebooks, a
shard whose run did not finish (resume it first with --resume).
"""

_MERGE_EPILOG = """\
examples:
  uio-teach merge marks/grades_1.csv marks/grades_2.csv marks/grades_3.csv --out grades.csv
  uio-teach merge marks/grades_*.csv --out grades.csv

exit status:
  0 merged, 1 the merged gradebook could not be written, 2 the gradebooks
  cannot be merged (the message says why).
"""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line: ``uio-teach labs: error: ...``.

    A description given as a function is made only when the help is shown (the labs' help
    lists what a term config sets that labs ignore, which loads the labs: no other command
    pays for that, and grading starts sooner).
    """

    def __init__(self, *args: Any, description: Any = None, **kwargs: Any) -> None:
        self._describe = description if callable(description) else None
        super().__init__(
            *args, description=None if callable(description) else description, **kwargs
        )

    def format_help(self) -> str:
        if self._describe is not None:
            self.description, self._describe = self._describe(), None
        return super().format_help()

    def error(self, message: str) -> NoReturn:
        text = " ".join(str(message).split())
        _say(f"{self.prog}: error: {text} (see {self.prog} --help)", sys.stderr)
        raise SystemExit(2)


def _say(text: str, stream: TextIO | None = None) -> None:
    """Print a line; if the reader has gone (``... | head -1``), stop printing, quietly.

    The run itself goes on (a run of ``figures`` or ``labs`` still writes its
    folder); only its messages are dropped from then on.
    """
    stream = stream or sys.stdout
    try:
        print(text, file=stream, flush=True)
    except BrokenPipeError:
        _drop_stream(stream)


def _drop_stream(stream: TextIO) -> None:
    """Point a stream whose reader has gone at /dev/null, so nothing more fails on it."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, stream.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # a stream without a file descriptor
        if stream is sys.stdout:
            sys.stdout = open(os.devnull, "w")  # noqa: SIM115 (kept open until the end)
        elif stream is sys.stderr:
            sys.stderr = open(os.devnull, "w")  # noqa: SIM115


def _load_config(command: str, path: str | None) -> FigureConfig | None:
    """The term config of ``--config``, or ``None`` after printing one line per problem."""
    try:
        return load_config(path)
    except ConfigError as err:
        for problem in err.problems:
            _error(command, problem)
    except UnicodeDecodeError as err:
        _error(
            command,
            f"{path}: not a text file in UTF-8 (byte 0x{err.object[err.start]:02x} at "
            f"position {err.start}); a config is a TOML file, see `uio-teach figures "
            "--print-config`",
        )
    except (ValueError, OSError) as err:  # anything else a file can do to the reader
        _error(command, f"{path}: cannot read it as a config ({' '.join(str(err).split())})")
    return None


class _Formatter(argparse.RawDescriptionHelpFormatter):
    def __init__(self, prog: str) -> None:
        super().__init__(prog, max_help_position=30, width=88)


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {value}")
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"expected a positive number of seconds, got {text}")
    return value


def _dpi(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        low, high = DPI_RANGE
        raise argparse.ArgumentTypeError(
            f"expected an integer between {low} and {high}, got {text!r}"
        ) from None
    try:
        return check_dpi(value)
    except ConfigError as err:
        raise argparse.ArgumentTypeError(str(err).removeprefix("dpi: ")) from None


def _labs_description() -> str:
    from .labs import UNREAD_CONFIG_KEYS  # deferred on purpose (see the imports)

    lines = []
    for entry in UNREAD_CONFIG_KEYS:
        lines += textwrap.wrap(
            entry.text(), width=76, initial_indent="  * ", subsequent_indent="    "
        )
    return _LABS_DESCRIPTION.replace("{unread}", "\n".join(lines))


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``uio-teach`` (with the ``figures`` and ``labs`` commands).

    Returns
    -------
    argparse.ArgumentParser

    Examples
    --------
    >>> from uio_teach.instructor.cli import build_parser
    >>> args = build_parser().parse_args(["figures", "--out", "figs", "--format", "svg"])
    >>> args.command, args.out, args.format, args.dpi
    ('figures', 'figs', 'svg', 150)
    """
    parser = _Parser(
        prog=PROG,
        description=_MAIN_DESCRIPTION,
        epilog=_MAIN_EPILOG,
        formatter_class=_Formatter,
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    fig = commands.add_parser(
        "figures",
        help="regenerate every figure of the course",
        description=_FIGURES_DESCRIPTION,
        epilog=_FIGURES_EPILOG,
        formatter_class=_Formatter,
    )
    fig.add_argument("--out", metavar="DIR", help="output folder (created if needed)")
    fig.add_argument(
        "--format",
        choices=FORMATS,
        default="png",
        help="image format (default: png); tables are always .csv and .md",
    )
    fig.add_argument(
        "--only",
        nargs="+",
        action="extend",
        metavar="NAME",
        help="make only these figures (names from --list)",
    )
    fig.add_argument(
        "--dpi",
        type=_dpi,
        default=150,
        metavar="N",
        help=f"resolution, {DPI_RANGE[0]} to {DPI_RANGE[1]} (default: 150)",
    )
    fig.add_argument(
        "--config", metavar="FILE", help="TOML file with this term's parameters (see below)"
    )
    fig.add_argument(
        "--list", action="store_true", help="name every figure with a one-line description"
    )
    fig.add_argument(
        "--print-config",
        action="store_true",
        help="print the default configuration (every key, commented) and exit",
    )
    fig.add_argument("-q", "--quiet", action="store_true", help="no progress lines")

    labs = commands.add_parser(
        "labs",
        help="write the lab notebooks (student and solution versions)",
        description=_labs_description,
        epilog=_LABS_EPILOG,
        formatter_class=_Formatter,
    )
    labs.add_argument("--out", metavar="DIR", required=True, help="output folder")
    labs.add_argument(
        "--book",
        metavar="DIR",
        help="the book's chapters (default: book/ of a checkout, else the installed copy)",
    )
    labs.add_argument(
        "--source",
        nargs="+",
        action="extend",
        metavar="FILE",
        help="convert these lab chapters only (default: every *lab*.md of the book)",
    )
    labs.add_argument(
        "--config", metavar="FILE", help="TOML file with this term's parameters (as for figures)"
    )
    labs.add_argument(
        "--groups",
        metavar="N",
        type=_positive_int,
        help="one variant per group: N student and N solution notebooks per lab, and the key",
    )
    labs.add_argument(
        "--seed",
        metavar="S",
        type=_seed,
        default=None,
        help="seed of the variants (with --groups; default 0)",
    )
    labs.add_argument("-q", "--quiet", action="store_true", help="no progress lines")

    grade = commands.add_parser(
        "grade",
        help="run handed-in notebooks and write a gradebook (runs the students' code)",
        description=_GRADE_DESCRIPTION,
        epilog=_GRADE_EPILOG,
        formatter_class=_Formatter,
    )
    grade.add_argument(
        "submissions",
        nargs="+",
        metavar="HANDIN",
        help="the hand-in folder, or the handed-in .ipynb files",
    )
    grade.add_argument("--out", metavar="FILE", required=True, help="the gradebook CSV to write")
    grade.add_argument(
        "--groups-from",
        metavar="KEY",
        help="answer_key.csv of `uio-teach labs --groups`: run each with its group's parameters",
    )
    grade.add_argument(
        "--roster",
        metavar="CSV",
        help="groups.csv naming each hand-in's group (columns group, file; student, name, lab)",
    )
    grade.add_argument(
        "--check-timeout",
        type=_positive_float,
        default=120.0,
        metavar="S",
        help="seconds the checks of one hand-in may take (default: 120)",
    )
    grade.add_argument(
        "--timeout",
        type=_positive_float,
        default=300.0,
        metavar="S",
        help="seconds a notebook may run in all (default: 300)",
    )
    grade.add_argument(
        "--cell-timeout",
        type=_positive_float,
        default=60.0,
        metavar="S",
        help="seconds a cell may run before it is interrupted (default: 60)",
    )
    grade.add_argument(
        "--resume",
        action="store_true",
        help="keep the rows already in the gradebook; grade only the submissions without one",
    )
    grade.add_argument(
        "--jobs",
        type=_positive_int,
        default=1,
        metavar="N",
        help="grade N submissions at a time (default: 1)",
    )
    grade.add_argument(
        "--no-sandbox",
        action="store_true",
        help="run the notebooks WITHOUT isolation, with your permissions (trusted notebooks only)",
    )
    grade.add_argument(
        "--shard",
        metavar="K/N",
        type=_shard,
        default=None,
        help="grade only shard K of N of the hand-ins (merge the N gradebooks with merge)",
    )
    grade.add_argument("-q", "--quiet", action="store_true", help="no progress lines")

    merge = commands.add_parser(
        "merge",
        help="merge the gradebooks of a class graded in shards",
        description=_MERGE_DESCRIPTION,
        epilog=_MERGE_EPILOG,
        formatter_class=_Formatter,
    )
    merge.add_argument(
        "gradebooks", nargs="+", metavar="GRADEBOOK", help="the gradebook CSV of every shard"
    )
    merge.add_argument("--out", metavar="FILE", required=True, help="the merged gradebook CSV")
    merge.add_argument("-q", "--quiet", action="store_true", help="no summary line")
    return parser


def _shard(text: str) -> tuple[int, int]:
    from ..grading.merge import parse_shard  # deferred on purpose (see the imports)
    from ..grading.rosters import GradeError  # deferred on purpose (see the imports)

    try:
        return parse_shard(text)
    except GradeError as err:
        raise argparse.ArgumentTypeError(str(err).removeprefix("shard: ")) from None


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a non-negative integer, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a non-negative integer, got {value}")
    return value


def _error(command: str, message: str, stream: TextIO | None = None) -> None:
    text = " ".join(str(message).split())
    _say(f"{PROG} {command}: error: {text}", stream or sys.stderr)


def _figures(args: argparse.Namespace) -> int:
    from . import figures  # deferred on purpose (see the imports)

    if args.list:
        width = max(len(name) for name in figures.FIGURES)
        for name, spec in figures.FIGURES.items():
            _say(f"{name:<{width}}  {spec.description}")
        return 0
    if args.print_config:
        _say(figures.default_config_toml().rstrip("\n"))
        return 0
    if not args.out:
        _error("figures", "--out DIR is required (or use --list or --print-config)")
        return 2
    for name in args.only or []:
        if name not in figures.FIGURES:
            _error("figures", figures.unknown_figure_message(name))
            return 2
    config = _load_config("figures", args.config)
    if config is None:
        return 2
    out = args.out
    try:
        check_output_folder(out, "uio-teach figures")
    except OSError as err:
        _error("figures", str(err))
        return 1

    matplotlib.use("Agg")  # no display needed, and the same pixels everywhere

    start = time.perf_counter()

    def progress(index: int, total: int, result: figures.FigureResult) -> None:
        if not result.ok:
            _error("figures", f"{result.name} failed: {result.error}")
        elif not args.quiet:
            files = ", ".join(os.fspath(p) for p in result.paths)
            count = f"[{index:>{len(str(total))}}/{total}]"
            _say(f"{count} {result.name}: {files} ({result.seconds:.1f} s)")

    try:
        results = figures.generate(
            out, args.only, fmt=args.format, dpi=args.dpi, config=config, progress=progress
        )
    except OSError as err:
        _error("figures", str(err) if isinstance(err, OutputError) else f"{out}: {err}")
        return 1
    elapsed = time.perf_counter() - start
    failed = [r.name for r in results if not r.ok]
    files = sum(len(r.paths) for r in results)
    done = len(results) - len(failed)
    if failed:
        left = "left as it was" if os.path.isdir(out) else "not created"
        _error(
            "figures",
            f"{done} of {len(results)} figures made, failed: {', '.join(failed)}; nothing was "
            f"written, {os.fspath(out)} {left}",
        )
        return 1
    summary = f"{done} of {len(results)} figures ({files} files) and {MANIFEST} "
    summary += f"written to {os.fspath(out)} in {elapsed:.1f} s"
    if not args.quiet:
        _say(summary)
    return 0


def _labs(args: argparse.Namespace) -> int:
    from . import labs  # deferred on purpose (see the imports)

    start = time.perf_counter()
    if args.seed is not None and args.groups is None:
        _error("labs", "--seed needs --groups N (the seed of the groups' variants)")
        return 2
    config = None
    if args.config:
        config = _load_config("labs", args.config)
        if config is None:
            return 2

    def progress(index: int, total: int, result: labs.LabResult) -> None:
        if not args.quiet:
            group = f" {result.group}" if result.group else ""
            _say(
                f"[{index}/{total}] {result.source.name}{group}: {os.fspath(result.student)} "
                f"({result.todo_cells} TODO cells), {os.fspath(result.solution)}"
            )

    try:
        with warnings.catch_warnings(record=True) as notes:
            warnings.simplefilter("always", labs.ConfigNotKeptWarning)
            results = labs.write_labs(
                args.out,
                args.source,
                book_dir=args.book,
                progress=progress,
                config=config,
                groups=args.groups,
                seed=args.seed or 0,
            )
        # a configured value the labs do not keep is said, never dropped unseen
        for note in notes:
            if issubclass(note.category, labs.ConfigNotKeptWarning):
                _say(f"{PROG} labs: note: {note.message}", sys.stderr)
            else:
                warnings.showwarning(
                    note.message, note.category, note.filename, note.lineno, note.file, note.line
                )
    except ImportError as err:
        missing = err.name or str(err)
        _error(
            "labs",
            f"the lab notebooks need {missing}, which is not installed: "
            "pip install 'uio-teach[instructor]' (in a checkout, `make venv` installs it)",
        )
        return 1
    except labs.LabUsageError as err:
        _error("labs", str(err))
        return 2
    except (labs.LabError, OSError) as err:
        _error("labs", str(err))
        return 1
    if not args.quiet:
        elapsed = time.perf_counter() - start
        n = len(results)
        plural = "s" if n != 1 else ""
        what = f"{n} lab{plural}" if args.groups is None else f"{n} lab variant{plural}"
        key = f", and {labs.ANSWER_KEY}" if args.groups is not None else ""
        _say(
            f"{what} written to {os.fspath(args.out)}: {n} student and {n} solution "
            f"notebook{plural}{key} and {MANIFEST} in {elapsed:.1f} s"
        )
    return 0


def _grade(args: argparse.Namespace) -> int:
    from ..grading import grade  # deferred on purpose (see the imports)

    missing = [p for p in args.submissions if not os.path.lexists(p)]
    if missing:
        _error("grade", f"no such hand-in: {', '.join(missing)}")
        return 2
    folders = [p for p in args.submissions if os.path.isdir(p) and not os.path.islink(p)]
    if folders and len(args.submissions) > 1:
        _error("grade", "give one hand-in folder, or the hand-in files, not both")
        return 2
    submissions = folders[0] if folders else args.submissions
    start = time.perf_counter()

    def progress(index: int, total: int, sub: grade.Submission) -> None:
        if not args.quiet:
            verdicts = sub.verdicts()
            why = f": {sub.reason}" if sub.reason and sub.needs_a_look else ""
            _say(
                f"[{index}/{total}] {sub.file}: lab {sub.lab or '?'}, group {sub.group or '?'}, "
                f"{sub.total} of {len(verdicts)} checks passed, {sub.status}{why} "
                f"({sub.seconds:.1f} s)"
            )

    if args.no_sandbox:
        _error(
            "grade",
            "WARNING: --no-sandbox: the notebooks run with your permissions; a notebook can "
            "read the answer key and your files, change the gradebook and end your processes",
        )
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", grade.UnsandboxedWarning)
            results = grade.grade(
                submissions,
                args.out,
                answer_key=args.groups_from,
                roster=args.roster,
                timeout=args.timeout,
                cell_timeout=args.cell_timeout,
                check_timeout=args.check_timeout,
                progress=progress,
                resume=args.resume,
                jobs=args.jobs,
                sandbox=not args.no_sandbox,
                shard=args.shard,
            )
    except ImportError as err:
        _error(
            "grade",
            f"grading needs {err.name or err}, which is not installed: "
            "pip install 'uio-teach[instructor]' (in a checkout, `make venv` installs it)",
        )
        return 1
    except grade.GradeError as err:
        _error("grade", str(err))
        return 2
    except OSError as err:
        _error("grade", f"cannot write the gradebook {args.out}: {_os_error(err)}")
        return 1
    out = Path(args.out)
    _not_graded(results, quiet=args.quiet)
    if not args.quiet:
        elapsed = time.perf_counter() - start
        part = f" (shard {args.shard[0]}/{args.shard[1]})" if args.shard else ""
        _say(
            f"{len(results)} hand-in{'s' if len(results) != 1 else ''} graded{part} in "
            f"{elapsed:.1f} s: {out}, feedback in {out.with_name(f'{out.stem}_feedback')}"
        )
    _summary("grade", out, roster=args.roster is not None, quiet=args.quiet)
    return 0


def _not_graded(results: Any, *, quiet: bool) -> None:
    """A line for every entry of the hand-in folder that has no row, and what the folder held.

    The folders of an LMS's download are listed only without ``--quiet`` (their entries have
    their own lines); every other entry always, on the standard error.
    """
    found = getattr(results, "survey", None)
    if found is None:
        return
    added = list(getattr(results, "added", []))
    for path, why in found.others:
        if not (quiet and why.startswith("a folder:")):
            _say(f"not graded: {path}: {why}", sys.stderr)
    for path, why in added:
        _say(f"not graded: {path}: {why}", sys.stderr)
    more = f", and {len(added)} added during the run, not graded" if added else ""
    if found.others or added or not quiet:
        _say(f"the hand-in folder {found.folder} held {found.counts()}{more}", sys.stderr)


def _os_error(err: OSError) -> str:
    """An OSError in one line, naming its file."""
    why = err.strerror or str(err)
    return f"{why}: {err.filename}" if err.filename else why


def _summary(command: str, out: Path, *, roster: bool, quiet: bool) -> None:
    """How many rows of the whole gradebook need a look (kept rows of a resumed run too)."""
    from ..grading.gradebook import needs_a_look, read_gradebook  # deferred on purpose

    header, rows = read_gradebook(out)
    at = header.index("status") if header else 3
    counts: dict[str, int] = {}
    for row in rows:
        if needs_a_look(row[at]):
            counts[row[at]] = counts.get(row[at], 0) + 1
    look = sum(counts.values())
    whole = f"{len(rows)} row{'s' if len(rows) != 1 else ''} in {out.name}"
    if look:
        kinds = ", ".join(f"{n} {status}" for status, n in counts.items())
        verb = "rows need" if look != 1 else "row needs"
        _say(f"{look} {verb} a look ({kinds}) of the {whole}", sys.stderr)
    elif not quiet:
        _say(f"no row needs a look of the {whole}")
    canvas = out.with_name(f"{out.stem}_canvas.csv")
    if roster and canvas.is_file() and header:
        import csv  # deferred on purpose: only this summary reads the export

        with open(canvas, newline="", encoding="utf-8") as fh:
            sections = {r[4] for r in list(csv.reader(fh))[2:] if len(r) > 4}
        group = header.index("group")
        alone = sorted({r[group] for r in rows if r[group]} - sections)
        if alone:
            _say(
                f"{len(alone)} group{'s' if len(alone) != 1 else ''} with no student in the "
                f"roster, not in {canvas.name}: {', '.join(alone[:10])}"
                + (" ..." if len(alone) > 10 else ""),
                sys.stderr,
            )
    if not roster and not quiet and command == "grade":
        _say(
            "no Canvas or Moodle import written: without --roster no group can be matched to "
            f"its students (give a roster with a student column to get {out.stem}_canvas.csv "
            f"and {out.stem}_moodle.csv)",
            sys.stderr,
        )


def _merge(args: argparse.Namespace) -> int:
    from ..grading.merge import (  # deferred on purpose (see the imports)
        MergeError,
        merge,
        shard_gradebooks,
    )

    missing = [p for p in args.gradebooks if not os.path.isfile(p)]
    if missing:
        _error("merge", f"no such gradebook: {', '.join(missing)}")
        return 2
    try:
        out = merge(args.gradebooks, args.out)
    except MergeError as err:
        _error("merge", str(err))
        return 2
    except OutputError as err:
        _error("merge", str(err))
        return 2
    except OSError as err:
        _error("merge", f"cannot write the gradebook {args.out}: {_os_error(err)}")
        return 1
    if not args.quiet:
        _say(f"{len(shard_gradebooks(args.gradebooks))} gradebooks merged into {out}")
    from ..grading.gradebook import export_path  # deferred on purpose (see the imports)

    _summary("merge", out, roster=export_path(out, "canvas").exists(), quiet=args.quiet)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``uio-teach`` with the arguments ``argv`` (default: the command line).

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments after the program name; ``sys.argv[1:]`` by default.

    Returns
    -------
    int
        The exit status: 0 success, 1 failure, 2 usage or configuration error.

    Examples
    --------
    >>> import tempfile
    >>> from uio_teach.instructor.cli import main
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     main(["figures", "--out", tmp, "--only", "case_error", "--dpi", "40", "-q"])
    0
    """
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:  # --help, --version and usage errors
        code = exit_.code
        return code if isinstance(code, int) else (0 if code is None else 2)
    except BrokenPipeError:  # `uio-teach --help | head -1`
        _drop_stream(sys.stdout)
        return 0
    try:
        if args.command == "figures":
            return _figures(args)
        if args.command == "grade":
            return _grade(args)
        if args.command == "merge":
            return _merge(args)
        return _labs(args)
    except KeyboardInterrupt:
        _error(args.command, "interrupted")
        return 130
