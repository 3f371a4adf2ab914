"""Headless Chromium driven over the DevTools protocol through a pipe (``--remote-debugging-pipe``: JSON
messages ending in NUL on file descriptors 3 and 4), with no Python package beyond the standard library.

The page runs with the network off: DevTools' offline emulation, a proxy at a closed local port and a host
resolver that resolves nothing, so a request to any server fails and is recorded (``Page.failures``).
"""

from __future__ import annotations

import base64
import fcntl
import io
import json
import os
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

LOCAL_SCHEMES = ("file:", "data:", "blob:", "about:")


def chromium() -> str | None:
    return next((p for p in (shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome")) if p), None)


def need_chromium() -> str:
    exe = chromium()
    if exe is None:
        if os.environ.get("CELLSTRESS_REQUIRE_CHROMIUM"):
            pytest.fail("CELLSTRESS_REQUIRE_CHROMIUM is set but no chromium is installed")
        pytest.skip("chromium is not installed (apt-get install chromium; CI installs it)")
    return exe


class Page:
    """One browser with one page; ``failures`` lists every request to a server, failed load and console error."""

    def __init__(self, exe: str, profile: Path, width: int = 1200, height: int = 1000):
        to_child_r, self._w = os.pipe()
        self._r, from_child_w = os.pipe()

        def fds():  # the child's fds 3 and 4 are the pipe's ends, as --remote-debugging-pipe expects
            a = fcntl.fcntl(to_child_r, fcntl.F_DUPFD, 10)  # (first out of the way: either end may be 3 or 4)
            b = fcntl.fcntl(from_child_w, fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.proc = subprocess.Popen(
            [exe, "--headless", "--no-sandbox", "--remote-debugging-pipe", f"--user-data-dir={profile}",
             f"--window-size={width},{height}", "--hide-scrollbars", "--no-first-run", "--disable-extensions",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--proxy-server=127.0.0.1:9",
             "--host-resolver-rules=MAP * ~NOTFOUND", "about:blank"],
            pass_fds=(3, 4, to_child_r, from_child_w), preexec_fn=fds, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL)
        os.close(to_child_r)
        os.close(from_child_w)
        self._buf = b""
        self._id = 0
        self.events: list[dict] = []
        self.failures: list[str] = []
        self.requests: list[str] = []
        self.session = None
        target = next(t for t in self.call("Target.getTargets")["targetInfos"] if t["type"] == "page")
        self.session = self.call("Target.attachToTarget", targetId=target["targetId"], flatten=True)["sessionId"]
        for domain in ("Page", "Runtime", "Log", "Network"):
            self.call(f"{domain}.enable")
        self.call("Network.emulateNetworkConditions", offline=True, latency=0, downloadThroughput=-1,
                  uploadThroughput=-1)
        self.call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=False)

    # ---- the protocol --------------------------------------------------------------------------------------
    def _read(self, deadline: float) -> dict:
        while b"\0" not in self._buf:
            if time.monotonic() > deadline:
                raise TimeoutError("no answer from chromium")
            chunk = os.read(self._r, 1 << 20)
            if not chunk:
                raise RuntimeError("chromium closed the pipe")
            self._buf += chunk
        msg, self._buf = self._buf.split(b"\0", 1)
        return json.loads(msg)

    def call(self, method: str, timeout: float = 60.0, **params) -> dict:
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params}
        if self.session is not None:
            msg["sessionId"] = self.session
        os.write(self._w, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            got = self._read(deadline)
            if got.get("id") == self._id:
                if "error" in got:
                    raise RuntimeError(f"{method}: {got['error']}")
                return got.get("result", {})
            self._event(got)

    def _event(self, ev: dict) -> None:
        self.events.append(ev)
        method, p = ev.get("method"), ev.get("params", {})
        if method == "Network.requestWillBeSent":
            url = p["request"]["url"]
            self.requests.append(url)
            if not url.startswith(LOCAL_SCHEMES):
                self.failures.append(f"request to a server: {url[:200]}")
        elif method == "Network.loadingFailed":
            self.failures.append(f"failed load: {p.get('errorText')}")
        elif method == "Runtime.exceptionThrown":
            self.failures.append(f"exception: {json.dumps(p.get('exceptionDetails'))[:500]}")
        elif method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            self.failures.append(f"console.{p['type']}: {json.dumps(p.get('args'))[:500]}")
        elif method == "Log.entryAdded" and p["entry"].get("level") == "error":
            self.failures.append(f"log error: {p['entry'].get('text', '')[:500]}")

    # ---- what a test does ----------------------------------------------------------------------------------
    def open(self, path: Path) -> None:
        self.call("Page.navigate", url=path.resolve().as_uri())

    def js(self, expression: str, timeout: float = 60.0):
        got = self.call("Runtime.evaluate", timeout=timeout, expression=expression, awaitPromise=True,
                        returnByValue=True)
        if "exceptionDetails" in got:
            raise RuntimeError(f"{expression}: {got['exceptionDetails']}")
        return got["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 120.0) -> None:
        deadline = time.monotonic() + timeout
        while not self.js(expression):
            if time.monotonic() > deadline:
                raise TimeoutError(f"not true within {timeout} s: {expression}")
            time.sleep(0.2)

    def screenshot(self, clip: dict | None = None) -> np.ndarray:
        params = {"format": "png", "captureBeyondViewport": True}
        if clip is not None:
            params["clip"] = {**clip, "scale": 1}
        data = self.call("Page.captureScreenshot", **params)["data"]
        with Image.open(io.BytesIO(base64.b64decode(data))) as img:
            return np.asarray(img.convert("RGB"), dtype=np.int16)

    def close(self) -> None:
        try:
            self.call("Browser.close", timeout=10)
        except (RuntimeError, TimeoutError, OSError):
            pass
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self._w)
        os.close(self._r)
