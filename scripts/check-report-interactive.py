#!/usr/bin/python3
"""Checks a dynid report's interactive parts in headless Chromium (docs/report.md), through the DevTools protocol
on a pipe (Python's standard library only):

  - every zoomable plot drew (the page counts plots that rendered an SVG: data-plots-drawn = data-plots);
  - every 3D mode-shape view animates: at least --frames frames rendered and two pictures whose displacements
    differ by 0.7 of the amplitude (about a quarter period apart) differ (data-frames, data-frames-differ), WebGL
    available (data-webgl = 1);
  - the page makes no network request: every request the browser reports (Network.requestWillBeSent) is to a
    file:, data: or blob: URL, and the page's Content-Security-Policy reported no violation.

  scripts/check-report-interactive.py REPORT.html [--screenshot FILE.png] [--frames 30] [--timeout 60]
Exit code 0 when all hold; 1 with the reasons otherwise; 2 for usage errors or no Chromium.
"""
import argparse
import base64
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time


class Browser:
    """Chromium with --remote-debugging-pipe: commands on fd 3, replies and events on fd 4 (NUL-separated JSON)."""

    def __init__(self, exe):
        self.profile = tempfile.mkdtemp(prefix="dynid-check-")
        to_child_r, self.to_child = os.pipe()
        self.from_child, from_child_w = os.pipe()

        def fds():  # in the child: the command pipe on fd 3, the reply pipe on fd 4 (via copies: they may be 3 or 4)
            r, w = os.dup(to_child_r), os.dup(from_child_w)
            os.dup2(r, 3)
            os.dup2(w, 4)

        # --no-sandbox: CI runs as root, where Chromium's sandbox refuses to start. The background services are
        # off so that the only requests are the page's own.
        flags = ["--headless", "--no-sandbox", "--remote-debugging-pipe", "--hide-scrollbars", "--disable-dev-shm-usage",
                 "--no-first-run", "--no-default-browser-check", "--disable-background-networking", "--disable-sync",
                 "--disable-component-update", "--disable-default-apps", "--disable-extensions", "--metrics-recording-only",
                 "--window-size=1400,3000", f"--user-data-dir={self.profile}", "about:blank"]
        self.proc = subprocess.Popen([exe, *flags], preexec_fn=fds, pass_fds=(3, 4, to_child_r, from_child_w),
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(to_child_r)
        os.close(from_child_w)
        self.buffer = b""
        self.next_id = 0
        self.events = []

    def close(self):
        try:
            self.send("Browser.close")
        except Exception:
            pass
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        shutil.rmtree(self.profile, ignore_errors=True)

    def _read(self, deadline):
        while b"\0" not in self.buffer:
            if time.time() > deadline:
                raise TimeoutError("no reply from Chromium")
            chunk = os.read(self.from_child, 1 << 20)
            if not chunk:
                raise RuntimeError("Chromium closed the pipe")
            self.buffer += chunk
        msg, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(msg)

    def send(self, method, session=None, timeout=60, **params):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params}
        if session:
            msg["sessionId"] = session
        os.write(self.to_child, json.dumps(msg).encode() + b"\0")
        deadline = time.time() + timeout
        while True:
            r = self._read(deadline)
            if r.get("id") == self.next_id:
                if "error" in r:
                    raise RuntimeError(f"{method}: {r['error']}")
                return r.get("result", {})
            self.events.append(r)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("report")
    ap.add_argument("--screenshot")
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--timeout", type=float, default=60)
    a = ap.parse_args()
    report = pathlib.Path(a.report).resolve()
    if not report.is_file():
        print(f"check-report-interactive: {a.report}: no such file", file=sys.stderr)
        return 2
    exe = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    if not exe:
        print("check-report-interactive: no Chromium found; scripts/setup.sh installs Debian's chromium package", file=sys.stderr)
        return 2
    b = Browser(exe)
    failures = []
    try:
        target = next(t for t in b.send("Target.getTargets")["targetInfos"] if t["type"] == "page")
        s = b.send("Target.attachToTarget", targetId=target["targetId"], flatten=True)["sessionId"]
        b.send("Network.enable", s)
        b.send("Page.enable", s)
        b.send("Runtime.enable", s)
        b.send("Page.navigate", s, url=report.as_uri())
        deadline = time.time() + a.timeout
        state = {}
        while time.time() < deadline:
            state = b.send("Runtime.evaluate", s, returnByValue=True, expression=(
                "(function(){var d=document.body?document.body.dataset:{};return {plots:+d.plots||0,views:+d.views||0,"
                "drawn:+d.plotsDrawn||0,frames:+d.frames||0,differ:d.framesDiffer,webgl:d.webgl,csp:+d.cspViolations||0,"
                "snapshots:d.snapshots,ready:document.readyState};})()"))["result"].get("value", {})
            if (state.get("ready") == "complete" and state["drawn"] >= state["plots"] and
                    (state["views"] == 0 or (state["frames"] >= a.frames and state.get("differ") is not None))):
                break
            time.sleep(0.5)
        if a.screenshot:
            shot = b.send("Page.captureScreenshot", s, format="png")
            pathlib.Path(a.screenshot).write_bytes(base64.b64decode(shot["data"]))
        requests = [e["params"]["request"]["url"] for e in b.events if e.get("method") == "Network.requestWillBeSent"]
    finally:
        b.close()
    if state.get("plots", 0) == 0 and state.get("views", 0) == 0:
        failures.append("the page has no interactive plot or view (data-plots, data-views)")
    if state.get("drawn", 0) != state.get("plots", 0):
        failures.append(f"{state.get('drawn', 0)} of {state.get('plots', 0)} zoomable plots drew")
    if state.get("views", 0):
        if state.get("webgl") != "1":
            failures.append("no WebGL: the 3D view could not start")
        if state.get("frames", 0) < a.frames:
            failures.append(f"the 3D view rendered {state.get('frames', 0)} frames (at least {a.frames} expected)")
        if state.get("differ") != "1":
            failures.append("the 3D view's pictures a quarter period apart do not differ: the shape does not move "
                            f"({state.get('snapshots') or 'no second picture taken'})")
    if state.get("csp", 0):
        failures.append(f"{state['csp']} Content-Security-Policy violations (the page tried to load something)")
    outside = [u for u in requests if not u.startswith(("file:", "data:", "blob:"))]
    if outside:
        failures.append(f"network requests: {', '.join(outside[:5])}")
    if failures:
        for f in failures:
            print(f"check-report-interactive: {report}: {f}", file=sys.stderr)
        return 1
    print(f"check-report-interactive: {report}: {state['drawn']} of {state['plots']} plots drawn, {state['views']} 3D views, "
          f"{state['frames']} frames rendered, moving; {len(requests)} requests, all local (file:, data:, blob:); no CSP violation")
    return 0


if __name__ == "__main__":
    sys.exit(main())
