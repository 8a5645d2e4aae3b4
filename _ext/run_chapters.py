"""Execute the book's chapters in parallel into the execution cache, before the book is built.

``jupyter-book build`` executes the chapters one after another (``execute_notebooks: cache``
in ``_config.yml``): a chapter whose code has not changed since its last run is taken from the
execution cache, any other is run there and then. This script runs every chapter that the cache
does not hold, as many at a time as there are cores, and stores each result in the same cache,
so the build that follows finds them all there and only reads and writes pages::

    .venv/bin/python _ext/run_chapters.py [--cache _build/.jupyter_cache] [--jobs N]

``make book`` runs it first. Each chapter is read as the build reads it (MyST-NB's reader) and
executed as the build executes it (in ``book/``, the cell time limit of ``_config.yml``, no
errors allowed), so the cache's record matches the build's. A chapter that fails here is not
stored: the build runs it again and reports its error as it always does. Without this script
the build is the same, only slower.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
READER = {"type": "plugin", "name": "myst_nb_md"}  # MyST-NB's own reader of MyST notebooks


def chapters(root: Path = ROOT) -> list[Path]:
    """The pages of ``_toc.yml`` that are notebooks (MyST Markdown with a kernel)."""
    toc = yaml.safe_load((root / "_toc.yml").read_text(encoding="utf-8"))
    files = [toc["root"]]

    def walk(entries: list) -> None:
        for entry in entries or []:
            if "file" in entry:
                files.append(entry["file"])
            walk(entry.get("sections", []))
            walk(entry.get("chapters", []))

    for part in toc.get("parts", []):
        walk(part.get("chapters", []))
    walk(toc.get("chapters", []))
    pages = [root / f"{f}.md" for f in files]
    return [p for p in pages if p.is_file() and "kernelspec:" in p.read_text(encoding="utf-8")]


def _run(pk: int, cache_path: str, timeout: int, allow_errors: bool) -> tuple[str, float, str]:
    """Execute one staged chapter in its folder and cache it (in a worker process): its name,
    seconds, and the error's last line ("" when it ran)."""
    from jupyter_cache import get_cache
    from jupyter_cache.cache.db import NbProjectRecord
    from jupyter_cache.executors.utils import create_cache_bundle, single_nb_execution

    cache = get_cache(cache_path)
    project_nb = cache.get_project_notebook(pk)
    name = Path(project_nb.uri).name
    result = single_nb_execution(
        project_nb.nb,
        cwd=str(Path(project_nb.uri).parent),
        timeout=timeout,
        allow_errors=allow_errors,
        meta_override=True,  # as the build executes a chapter
    )
    if result.err is not None:
        NbProjectRecord.set_traceback(project_nb.uri, result.exc_string, cache.db)
        return name, result.time, f"{type(result.err).__name__}: {result.err}".splitlines()[0]
    bundle = create_cache_bundle(project_nb, result.cwd, None, result.time, result.exc_string)
    cache.cache_notebook_bundle(bundle, check_validity=False, overwrite=True)
    return name, result.time, ""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cache", type=Path, default=ROOT / "_build" / ".jupyter_cache")
    parser.add_argument(
        "--jobs", type=int, default=len(os.sched_getaffinity(0)), help="chapters at a time"
    )
    args = parser.parse_args(argv)

    from jupyter_cache import get_cache

    config = yaml.safe_load((ROOT / "_config.yml").read_text(encoding="utf-8"))["execute"]
    if config.get("execute_notebooks") != "cache" or config.get("run_in_temp"):
        print("run_chapters: the book does not execute into a cache in book/; nothing to do")
        return 0
    cache = get_cache(str(args.cache))
    pages = chapters()
    for page in pages:
        cache.add_nb_to_project(str(page), read_data=READER)
    # the longest chapters first (by the size of their code), so the last to finish is short
    size = {str(p): len(p.read_text(encoding="utf-8")) for p in pages}
    waiting = sorted(
        (r for r in cache.list_unexecuted() if r.uri in size), key=lambda r: -size[r.uri]
    )
    if not waiting:
        print("run_chapters: every chapter is in the execution cache")
        return 0
    jobs = max(1, min(args.jobs, len(waiting)))
    print(f"run_chapters: running {len(waiting)} chapter(s), {jobs} at a time", flush=True)
    start = time.perf_counter()
    timeout = int(config.get("timeout", 300))
    allow_errors = bool(config.get("allow_errors", False))
    failed = []
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        runs = {
            pool.submit(_run, r.pk, str(args.cache), timeout, allow_errors): Path(r.uri).name
            for r in waiting
        }
        for run in as_completed(runs):
            try:
                name, seconds, error = run.result()
            except Exception as exc:  # the worker itself failed (the cache's database, a crash)
                name, seconds, error = runs[run], 0.0, f"{type(exc).__name__}: {exc}"
            print(f"  {name}: {seconds:.1f} s" + (f", failed ({error})" if error else ""))
            if error:
                failed.append(name)
    print(
        f"run_chapters: {len(waiting) - len(failed)} chapter(s) cached in "
        f"{time.perf_counter() - start:.0f} s"
        + (f"; the build runs again and reports: {', '.join(failed)}" if failed else "")
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
