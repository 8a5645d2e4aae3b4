"""Headless Chromium for the tests that drive it (marked ``browser``): Debian's, started with
the arguments the printer starts it with (``_ext/pdf_print.py``), through Playwright."""

from __future__ import annotations

import os
import sys
import threading
from collections.abc import Callable
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "_ext"))

from pdf_print import CHROMIUM, CHROMIUM_ARGS  # noqa: E402


def require_chromium() -> None:
    """Skip the test where Debian's Chromium is not installed (fail it on CI)."""
    if not CHROMIUM.exists():
        message = f"chromium missing: {CHROMIUM} not found (apt-get install chromium)"
        if os.environ.get("CI") == "true":
            pytest.fail(message, pytrace=False)
        pytest.skip(message)


def launch(playwright):  # noqa: ANN001, ANN201 (Playwright's own types)
    """Chromium started by ``playwright`` (the synchronous API), headless."""
    return playwright.chromium.launch(
        executable_path=str(CHROMIUM), args=CHROMIUM_ARGS, headless=True
    )


def in_chromium(work: Callable[[object], None]) -> None:
    """Run ``work(browser)`` in headless Chromium, in a thread of its own (an earlier test, a
    notebook's execution, may leave an asyncio loop running in the main thread, where
    Playwright's synchronous API will not start); what it raises is raised here."""
    require_chromium()
    from playwright.sync_api import sync_playwright

    failure: list[BaseException] = []

    def drive() -> None:
        try:
            with sync_playwright() as playwright:
                browser = launch(playwright)
                try:
                    work(browser)
                finally:
                    browser.close()
        except BaseException as exc:  # re-raised in the test's thread
            failure.append(exc)

    thread = threading.Thread(target=drive)
    thread.start()
    thread.join()
    if failure:
        raise failure[0]
