#!/usr/bin/env python3
"""A still of the live page as a browser shows it, taken in real time (not on a virtual clock).

Usage: scripts/live_view_still.py [--url URL] [--at-frame N] [--size WxH] [--timeout S] OUT.png

Opens URL (default http://127.0.0.1:8080/) in headless Chromium, driven through the DevTools protocol on a pipe,
waits until the page has drawn scene frame N (default 120) or the run has finished, and writes the screenshot.
Start the recording first, for example:

  build/bin/palpate record scenes/bunny_pull.json --mode realtime --serve 8080 --serve-linger 10 &
  scripts/live_view_still.py --at-frame 150 out/live_view.png

Exit status 1 when the page never got that far (the page's state line is printed).
"""
import argparse
import base64
import json
import os
import subprocess
import sys
import time


class Chromium:
    """Headless Chromium with its DevTools protocol on fds 3 (commands in) and 4 (replies out), NUL-ended JSON."""

    def __init__(self, width, height):
        to_r, self.to_w = os.pipe()
        self.from_r, from_w = os.pipe()

        def fds():  # the child's fd 3 reads our commands, fd 4 writes its replies
            # copies first: a pipe end may itself be fd 3 or 4 (dup2 onto itself would keep it close-on-exec)
            read_end, write_end = os.dup(to_r), os.dup(from_w)
            os.dup2(read_end, 3)
            os.dup2(write_end, 4)

        self.proc = subprocess.Popen(
            ["chromium", "--headless=new", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
             "--remote-debugging-pipe", f"--window-size={width},{height}", "about:blank"],
            # fds 3 and 4 are made in the child after the fork; close_fds would close them again before exec (the
            # pipes' own descriptors are not inherited: Python makes them close-on-exec)
            preexec_fn=fds, close_fds=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(to_r)
        os.close(from_w)
        self.next_id = 0
        self.buf = b""
        self.session = None

    def call(self, method, params=None, on_page=True):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if on_page:
            msg["sessionId"] = self.session
        os.write(self.to_w, json.dumps(msg).encode() + b"\0")
        while True:
            while b"\0" not in self.buf:
                chunk = os.read(self.from_r, 1 << 16)
                if not chunk:
                    raise RuntimeError("chromium closed its DevTools pipe")
                self.buf += chunk
            raw, self.buf = self.buf.split(b"\0", 1)
            reply = json.loads(raw)
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})

    def open(self, url):
        target = self.call("Target.createTarget", {"url": "about:blank"}, on_page=False)["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True},
                                 on_page=False)["sessionId"]
        self.call("Page.navigate", {"url": url})

    def eval(self, expression):
        r = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True})
        return r.get("result", {}).get("value")

    def close(self):
        self.proc.kill()
        self.proc.wait()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--url", default="http://127.0.0.1:8080/")
    ap.add_argument("--at-frame", type=int, default=120)
    ap.add_argument("--size", default="1280x830")
    ap.add_argument("--timeout", type=float, default=60.0)
    a = ap.parse_args()
    width, height = (int(v) for v in a.size.lower().split("x"))
    browser = Chromium(width, height)
    try:
        browser.open(a.url)
        deadline = time.monotonic() + a.timeout
        navigated = time.monotonic()
        state = None
        while time.monotonic() < deadline:
            # a page opened before the server listened is an error page: open it again each second until it loads
            if state is None and time.monotonic() - navigated > 1.0:
                browser.call("Page.navigate", {"url": a.url})
                navigated = time.monotonic()
            state = browser.eval("typeof live === 'undefined' ? null : "
                                 "{frame: live.lastFrame, finished: !!live.finished, "
                                 "state: document.getElementById('state').textContent}")
            if state and ((state["frame"] or -1) >= a.at_frame or state["finished"]):
                break
            time.sleep(0.02)
        else:
            print(f"live_view_still: the page did not reach frame {a.at_frame} in {a.timeout:.0f} s: {state}",
                  file=sys.stderr)
            return 1
        shot = browser.call("Page.captureScreenshot", {"format": "png"})
        tmp = a.out + ".tmp"
        with open(tmp, "wb") as f:
            f.write(base64.b64decode(shot["data"]))
        os.replace(tmp, a.out)
        print(f"live_view_still: {a.out} at frame {state['frame']} ({state['state']})")
        return 0
    finally:
        browser.close()


if __name__ == "__main__":
    sys.exit(main())
