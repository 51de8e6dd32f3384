"""A headless Chromium driven over the DevTools protocol through a pipe (no extra dependency).

Chromium started with ``--remote-debugging-pipe`` reads protocol commands, JSON separated by a
NUL byte, from its file descriptor 3 and writes replies and events to descriptor 4. That is all
a test of the report needs: open a page, wait for its scripts, evaluate JavaScript, screenshot.
"""

from __future__ import annotations

import base64
import fcntl
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
from pathlib import Path

#: Debian's package (``apt-get install chromium``); CHROMIUM overrides.
CHROMIUM = os.environ.get("CHROMIUM", "/usr/bin/chromium")


def chromium_path() -> str | None:
    """The Chromium binary, or None when it is not installed."""
    if Path(CHROMIUM).is_file():
        return CHROMIUM
    return shutil.which("chromium")


def _pipe_to_3_and_4(read_end: int, write_end: int) -> None:
    """In the child before exec: the protocol pipe's ends become descriptors 3 and 4."""
    high_r = fcntl.fcntl(read_end, fcntl.F_DUPFD, 10)  # out of the way of 3 and 4 first
    high_w = fcntl.fcntl(write_end, fcntl.F_DUPFD, 10)
    os.dup2(high_r, 3)
    os.dup2(high_w, 4)


class Browser:
    """One headless Chromium with one page, ``width`` x ``height`` CSS pixels."""

    def __init__(self, width: int = 1400, height: int = 1000, timeout: float = 60.0) -> None:
        exe = chromium_path()
        if exe is None:
            raise FileNotFoundError(f"no Chromium at {CHROMIUM} nor on PATH (make test-report installs it)")
        self.timeout = timeout
        self._profile = tempfile.mkdtemp(prefix="ballbat-chromium-")
        to_chrome_r, self._to_chrome = os.pipe()
        self._from_chrome, from_chrome_w = os.pipe()
        # fds 3 and 4 in the child: Chromium's protocol pipe
        self._proc = subprocess.Popen(
            [
                exe,
                "--headless",
                "--no-sandbox",  # root in a container
                "--disable-gpu",
                "--disable-dev-shm-usage",
                "--hide-scrollbars",
                "--no-first-run",
                f"--user-data-dir={self._profile}",
                f"--window-size={width},{height}",
                "--remote-debugging-pipe",
                "about:blank",
            ],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            pass_fds=(3, 4),
            start_new_session=True,  # its helpers (renderer, crashpad) in one group, stopped together
            preexec_fn=lambda: _pipe_to_3_and_4(to_chrome_r, from_chrome_w),
        )
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        self._buffer = b""
        self._id = 0
        target = self._call("Target.createTarget", {"url": "about:blank"})["targetId"]
        self._session = self._call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        self.call("Page.enable")
        self.call(
            "Emulation.setDeviceMetricsOverride",
            {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
        )

    def __enter__(self) -> Browser:
        """Return the browser (closed at the end of the ``with`` block)."""
        return self

    def __exit__(self, *exc: object) -> None:
        """Close the browser."""
        self.close()

    def close(self) -> None:
        """Stop this Chromium and its helper processes, then remove its profile.

        Chromium's helpers (crashpad, renderer) can still be writing into the profile just
        after the main process has gone, so the whole process group is stopped and waited for,
        and the profile's removal is retried briefly; a profile left in /tmp is not a test failure.
        """
        try:
            self._call("Browser.close")  # graceful: flushes and ends the helpers
        except (OSError, RuntimeError, TimeoutError):
            pass
        for fd in (self._to_chrome, self._from_chrome):
            try:
                os.close(fd)
            except OSError:
                pass
        try:
            self._proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self._proc.kill()
            self._proc.wait()
        try:
            os.killpg(self._proc.pid, signal.SIGKILL)  # any helper still alive
        except (ProcessLookupError, PermissionError):
            pass
        for _ in range(20):
            try:
                shutil.rmtree(self._profile)
                break
            except FileNotFoundError:
                break
            except OSError:
                time.sleep(0.1)
        shutil.rmtree(self._profile, ignore_errors=True)

    def _read_message(self, deadline: float) -> dict:
        while b"\0" not in self._buffer:
            if time.monotonic() > deadline:
                raise TimeoutError("Chromium did not answer in time")
            chunk = os.read(self._from_chrome, 1 << 20)
            if not chunk:
                raise RuntimeError("Chromium closed its protocol pipe")
            self._buffer += chunk
        raw, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(raw)

    def _call(self, method: str, params: dict | None = None, session: str | None = None) -> dict:
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self._to_chrome, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + self.timeout
        while True:
            reply = self._read_message(deadline)
            if reply.get("id") == self._id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})

    def call(self, method: str, params: dict | None = None) -> dict:
        """A protocol command on the page."""
        return self._call(method, params, self._session)

    def open(self, url: str) -> None:
        """Navigate to ``url`` and wait until the page's load event has fired."""
        self.call("Page.navigate", {"url": url})
        self.wait_for("document.readyState === 'complete'")

    def evaluate(self, expression: str) -> object:
        """The value of a JavaScript expression in the page (promises awaited)."""
        res = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True})
        if "exceptionDetails" in res:
            raise RuntimeError(f"JavaScript error in {expression!r}: {res['exceptionDetails']}")
        return res["result"].get("value")

    def wait_for(self, condition: str, timeout: float | None = None) -> None:
        """Wait until a JavaScript condition holds."""
        deadline = time.monotonic() + (timeout or self.timeout)
        while not self.evaluate(f"Boolean({condition})"):
            if time.monotonic() > deadline:
                raise TimeoutError(f"page never satisfied {condition!r}")
            time.sleep(0.1)

    def screenshot(self, path: str | os.PathLike[str]) -> Path:
        """Save a PNG of the window as it is shown."""
        data = self.call("Page.captureScreenshot", {"format": "png"})["data"]
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(base64.b64decode(data))
        return path
