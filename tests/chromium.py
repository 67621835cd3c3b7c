"""Headless Chromium driven over the DevTools protocol on a pipe (standard library only).

The view's tests and ``benches/view.py`` open the HTML files it writes here: the
page sets ``window.cloudproxDrawn`` (``performance.now()``, milliseconds after
navigation started) two animation frames after its scene was drawn, so a caller
waits for that, then screenshots, moves the mouse or reads the page's state.

``--remote-debugging-pipe`` makes Chromium read commands from file descriptor 3
and write answers to 4, each a JSON text ended by a NUL byte.
"""

from __future__ import annotations

import base64
import json
import os
import select
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

#: Software WebGL (SwiftShader), as on a machine without a GPU; the same flag the
#: earlier ``--screenshot`` runs used.
FLAGS = ("--disable-gpu",)


_EXEC_WITH_FDS = (
    "import os, sys; os.dup2(int(sys.argv[1]), 3); os.dup2(int(sys.argv[2]), 4); "
    "os.close(int(sys.argv[1])); os.close(int(sys.argv[2])); os.execv(sys.argv[3], sys.argv[3:])"
)


def _above_9(fd: int) -> int:
    """The same pipe end on a descriptor above 9 (``fd`` closed)."""
    import fcntl

    high = fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10)
    os.close(fd)
    return high


def find_chromium() -> str | None:
    """Path of a Chromium (or Chrome) on PATH, or None."""
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        path = shutil.which(name)
        if path:
            return path
    return None


class Chromium:
    """One headless Chromium with one page, driven over the DevTools protocol.

    Parameters
    ----------
    size : (int, int)
        The page's viewport in CSS pixels (device scale 1).
    flags : sequence of str
        Extra command-line flags.
    settle : float
        Seconds to wait after start-up before the first page: headless Chromium
        keeps working for a while after it answers (it loads its own omnibox
        pages), which would otherwise be counted in the first page's time.
    """

    def __init__(
        self,
        size: tuple[int, int] = (1000, 800),
        flags: tuple[str, ...] = FLAGS,
        settle: float = 2.0,
        executable: str | None = None,
    ) -> None:
        exe = executable or find_chromium()
        if exe is None:
            raise FileNotFoundError("no chromium on PATH (scripts/system-deps.sh installs it)")
        self._profile = tempfile.mkdtemp(prefix="cloudprox-chromium-")
        cmd_r, self._cmd_w = os.pipe()
        self._res_r, res_w = os.pipe()
        # Chromium's ends go to fds 3 and 4 of the child. A fork-safe way (no
        # preexec_fn, which may deadlock in a process with threads): a Python
        # that moves them there and execs Chromium; above 9 first, so that the
        # moves cannot overwrite each other.
        cmd_r, res_w = (_above_9(fd) for fd in (cmd_r, res_w))
        args = [
            exe,
            "--headless",
            "--no-sandbox",
            "--remote-debugging-pipe",
            "--hide-scrollbars",
            "--no-first-run",
            f"--user-data-dir={self._profile}",
            f"--window-size={size[0]},{size[1]}",
            *flags,
            "about:blank",
        ]
        start = time.perf_counter()
        self._proc = subprocess.Popen(
            [sys.executable, "-c", _EXEC_WITH_FDS, str(cmd_r), str(res_w), *args],
            pass_fds=(cmd_r, res_w),
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        os.close(cmd_r)
        os.close(res_w)
        self._buf = b""
        self._id = 0
        self._session: str | None = None
        self.events: list[dict[str, Any]] = []
        try:
            self.call("Browser.getVersion")
            #: Seconds from launch (through the small Python launcher) to the first answer.
            self.startup_s = time.perf_counter() - start
            targets = self.call("Target.getTargets")["targetInfos"]
            page = next(t for t in targets if t["type"] == "page")
            self._session = self.call(
                "Target.attachToTarget", targetId=page["targetId"], flatten=True
            )["sessionId"]
            for domain in ("Page", "Runtime", "Network"):
                self.call(f"{domain}.enable", page=True)
            self.call(
                "Emulation.setDeviceMetricsOverride",
                page=True,
                width=size[0],
                height=size[1],
                deviceScaleFactor=1,
                mobile=False,
            )
            time.sleep(settle)
        except BaseException:
            self.close()
            raise

    def __enter__(self) -> Chromium:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _read(self, deadline: float) -> dict[str, Any]:
        while b"\0" not in self._buf:
            left = deadline - time.perf_counter()
            if left <= 0 or not select.select([self._res_r], [], [], left)[0]:
                raise TimeoutError("chromium did not answer in time")
            chunk = os.read(self._res_r, 1 << 20)
            if not chunk:
                raise RuntimeError("chromium closed its DevTools pipe")
            self._buf += chunk
        message, self._buf = self._buf.split(b"\0", 1)
        decoded: dict[str, Any] = json.loads(message)
        return decoded

    def call(self, method: str, page: bool = False, timeout: float = 120.0, **params: Any) -> Any:
        """Send one DevTools command (to the page if ``page``) and return its result."""
        self._id += 1
        message: dict[str, Any] = {"id": self._id, "method": method, "params": params}
        if page:
            message["sessionId"] = self._session
        os.write(self._cmd_w, json.dumps(message).encode() + b"\0")
        deadline = time.perf_counter() + timeout
        while True:
            answer = self._read(deadline)
            if answer.get("id") == self._id:
                if "error" in answer:
                    raise RuntimeError(f"{method}: {answer['error']}")
                return answer["result"]
            self.events.append(answer)

    def eval(self, expression: str) -> Any:
        """Evaluate a JavaScript expression in the page; its value (JSON-able)."""
        result = self.call("Runtime.evaluate", page=True, expression=expression, returnByValue=True)
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression}: {result['exceptionDetails']}")
        return result["result"].get("value")

    def open(self, path: str | Path, timeout: float = 60.0) -> float:
        """Load a file and wait until its page sets ``window.cloudproxDrawn``.

        Returns
        -------
        float
            The page's own time of drawing: seconds from navigation start.
        """
        self.eval("window.cloudproxDrawn = undefined")
        self.events.clear()
        self.call("Page.navigate", page=True, url=Path(path).resolve().as_uri())
        deadline = time.perf_counter() + timeout
        while time.perf_counter() < deadline:
            drawn = self.eval("window.cloudproxDrawn === undefined ? null : window.cloudproxDrawn")
            if drawn is not None:
                return float(drawn) / 1e3
            time.sleep(0.02)
        raise TimeoutError(f"{path} was not drawn within {timeout} s")

    def requests(self) -> list[str]:
        """URLs the page requested since :meth:`open` (the file itself first)."""
        return [
            e["params"]["request"]["url"]
            for e in self.events
            if e.get("method") == "Network.requestWillBeSent"
        ]

    def screenshot(self, png: str | Path) -> Path:
        """Write a PNG of the viewport."""
        data = self.call("Page.captureScreenshot", page=True, format="png")["data"]
        Path(png).write_bytes(base64.b64decode(data))
        return Path(png)

    def mouse(self, kind: str, x: float, y: float, **extra: Any) -> None:
        """Dispatch one mouse event (``mouseMoved``, ``mousePressed``, ``mouseWheel``, ...)."""
        self.call("Input.dispatchMouseEvent", page=True, type=kind, x=x, y=y, **extra)

    def drag(self, start: tuple[float, float], end: tuple[float, float], steps: int = 10) -> None:
        """Drag with the left button from ``start`` to ``end``."""
        self.mouse("mouseMoved", *start)
        self.mouse("mousePressed", *start, button="left", clickCount=1)
        for k in range(1, steps + 1):
            t = k / steps
            x = start[0] + t * (end[0] - start[0])
            y = start[1] + t * (end[1] - start[1])
            self.mouse("mouseMoved", x, y, button="left", buttons=1)
        self.mouse("mouseReleased", *end, button="left", clickCount=1)

    def close(self) -> None:
        """Close the browser and remove its profile."""
        if getattr(self, "_proc", None) is not None and self._proc.poll() is None:
            try:
                self.call("Browser.close", timeout=10.0)
            except (OSError, RuntimeError, TimeoutError):
                pass
            try:
                self._proc.wait(10)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait(10)
        for fd in ("_cmd_w", "_res_r"):
            if hasattr(self, fd):
                try:
                    os.close(getattr(self, fd))
                except OSError:
                    pass
                delattr(self, fd)
        shutil.rmtree(self._profile, ignore_errors=True)
