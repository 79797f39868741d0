#!/usr/bin/env python3
"""The studio's in-page benchmark (studio_browser.py --bench) without Selenium or chromedriver.

Drives Chromium, or Debian's `chromium-headless-shell`, over its DevTools pipe (--remote-debugging-pipe:
JSON messages ending in a NUL byte on file descriptors 3 and 4), with the standard library only, so that
it runs on a machine where nothing can be installed: a borrowed GPU machine, to measure the page with
a hardware WebGL instead of the software rasterizer of this project's CI machines.

Usage: studio_cdp.py --vitri PATH --chromium PATH --out DIR [--model FILE] [--precision P]
                     [--studio-args "..."] [--window W,H] [--query "aa=1"] [--gl FLAGSET | --flags "..."]
       studio_cdp.py --chromium PATH --probe   (the WebGL renderer under every flag set, then exit)
Flag sets (--gl): software (SwiftShader, as the CI test), vulkan, egl, default. Prints one BENCH line
with the same JSON as studio_browser.py --bench, plus the flags used. Exit status 0 ok, 1 failure.
"""
import argparse
import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from studio_server import Failure, Server, wait_for  # noqa: E402

GL_FLAGS = {
    "software": ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"],
    "vulkan": ["--use-angle=vulkan", "--enable-features=Vulkan", "--disable-vulkan-surface",
               "--ignore-gpu-blocklist"],
    "egl": ["--use-gl=angle", "--use-angle=gl-egl", "--ignore-gpu-blocklist"],
    "default": ["--ignore-gpu-blocklist"],
}

def webgl_renderer(context):
    """JavaScript: the renderer string of the WebGL context the expression `context` gives."""
    return """(() => { const gl = %s;
  if (!gl) return 'no WebGL';
  const e = gl.getExtension('WEBGL_debug_renderer_info');
  return e ? gl.getParameter(e.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER); })()""" % context


class Browser:
    """One headless Chromium and one page, driven over the DevTools pipe."""

    def __init__(self, chromium, flags, window, out_dir):
        self.profile = tempfile.mkdtemp(prefix="vitri-cdp-", dir=out_dir)
        # The pipe ends go to descriptors 3 (the browser reads) and 4 (the browser writes) of the child.
        to_browser_r, self.to_browser = os.pipe()
        self.from_browser, from_browser_w = os.pipe()
        high_r, high_w = os.dup(to_browser_r), os.dup(from_browser_w)
        while high_r < 5 or high_w < 5:  # out of the way of 3 and 4 before the child's dup2
            high_r, high_w = os.dup(high_r), os.dup(high_w)

        def child_fds():
            os.dup2(high_r, 3)
            os.dup2(high_w, 4)

        cmd = [chromium, "--headless=new", "--no-sandbox", "--remote-debugging-pipe", "--no-first-run",
               "--disable-background-networking", "--disable-component-update", "--disable-sync",
               "--disable-dev-shm-usage", "--window-size=" + window, "--user-data-dir=" + self.profile] + flags
        self.log = open(os.path.join(out_dir, "chromium.log"), "ab")
        self.proc = subprocess.Popen(cmd + ["about:blank"], preexec_fn=child_fds, close_fds=False,
                                     stdout=self.log, stderr=subprocess.STDOUT)
        for fd in (to_browser_r, from_browser_w, high_r, high_w):
            os.close(fd)
        self.buffer = b""
        self.next_id = 0
        self.session = None
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]

    def call(self, method, params=None, timeout=600, browser=False):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if self.session and not browser:
            msg["sessionId"] = self.session
        os.write(self.to_browser, json.dumps(msg).encode() + b"\0")
        deadline = time.time() + timeout
        while time.time() < deadline:
            while b"\0" not in self.buffer:
                chunk = os.read(self.from_browser, 1 << 20)
                if not chunk:
                    raise Failure("the browser closed its DevTools pipe (see chromium.log)")
                self.buffer += chunk
            raw, self.buffer = self.buffer.split(b"\0", 1)
            reply = json.loads(raw)
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise Failure("%s: %s" % (method, reply["error"]))
                return reply["result"]
        raise Failure("no answer to " + method)

    def evaluate(self, expression):
        """The value of a JavaScript expression in the page; a promise is awaited."""
        r = self.call("Runtime.evaluate", {"expression": expression, "awaitPromise": True, "returnByValue": True})
        if "exceptionDetails" in r:
            raise Failure(expression[:80] + ": " + json.dumps(r["exceptionDetails"])[:400])
        return r["result"].get("value")

    def screenshot(self, path):
        data = self.call("Page.captureScreenshot", {"format": "png"})["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))

    def close(self):
        try:
            self.call("Browser.close", browser=True, timeout=10)
        except Exception:
            pass
        try:
            self.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        self.log.close()
        shutil.rmtree(self.profile, ignore_errors=True)


def probe(args):
    """The WebGL renderer each flag set gives on a blank page."""
    for name, flags in GL_FLAGS.items():
        t0 = time.time()
        try:
            b = Browser(args.chromium, flags, args.window, args.out)
            try:
                renderer = b.evaluate(webgl_renderer("document.createElement('canvas').getContext('webgl2')"))
            finally:
                b.close()
        except Failure as e:
            renderer = "failed: " + str(e)
        print("PROBE %s: %s (%.1f s)" % (name, renderer, time.time() - t0), flush=True)
    return 0


def bench(args):
    flags = args.flags.split() if args.flags else GL_FLAGS[args.gl]
    server = Server(args.vitri, ([args.model] if args.model else []) + ["--precision", str(args.precision)] +
                    args.studio_args.split())
    browser = None
    try:
        browser = Browser(args.chromium, flags, args.window, args.out)
        browser.call("Page.enable")
        browser.call("Page.navigate", {"url": server.url + "/" + ("?" + args.query if args.query else "")})
        wait_for("the page to start", lambda: browser.evaluate("!!(window.studio && studio.ready)"))
        wait_for("refinement to the target precision", lambda: server.get("/api/stats")["refined"], 300)
        idle = "window.studio.busy.then(() => window.studio.drag === null)"
        wait_for("the page to be idle", lambda: browser.evaluate(idle))
        time.sleep(0.5)
        wait_for("the page to be idle", lambda: browser.evaluate(idle))
        stats = server.get("/api/stats")
        if browser.evaluate("studio.slots.triangles") != stats["triangles"]:
            raise Failure("the page draws another triangle count than the server holds")
        load = [os.getloadavg()[0]]
        adds = browser.evaluate("studio.benchAdd({count: 12})")
        drag = browser.evaluate("studio.benchDrag({moves: 60})")
        live = browser.evaluate("studio.benchDrag({moves: 120, live: true})")
        load.append(os.getloadavg()[0])
        browser.screenshot(os.path.join(args.out, "studio-bench.png"))
        version = browser.call("Browser.getVersion", browser=True)["product"]
        renderer = browser.evaluate(webgl_renderer("studio.renderer.getContext()"))
        print("BENCH " + json.dumps({"model": stats["name"], "load_average": load, "constraints": stats["constraints"],
                                     "triangles": stats["triangles"], "vertices": stats["vertices"],
                                     "browser": version, "webgl": renderer, "flags": flags,
                                     "antialias": browser.evaluate("studio.renderer.getContextAttributes().antialias"),
                                     "low_res_interaction": browser.evaluate("studio.lowResInteraction"),
                                     "add": adds["add"], "undo": adds["undo"],
                                     "target_after_add": adds["target_after_add"], "drag": drag, "live_drag": live},
                                    indent=1), flush=True)
        return 0
    finally:
        if browser:
            browser.close()
        server.stop()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--chromium", required=True, help="chromium or chromium-headless-shell binary")
    ap.add_argument("--vitri")
    ap.add_argument("--out", default=tempfile.gettempdir())
    ap.add_argument("--model", default="")
    ap.add_argument("--precision", type=float, default=0.02)
    ap.add_argument("--studio-args", default="")
    ap.add_argument("--window", default="1280,800")
    ap.add_argument("--query", default="")
    ap.add_argument("--gl", default="software", choices=sorted(GL_FLAGS))
    ap.add_argument("--flags", default="", help="browser flags instead of a --gl set (space-separated)")
    ap.add_argument("--probe", action="store_true")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    try:
        if args.probe:
            return probe(args)
        if not args.vitri:
            raise Failure("--vitri is required for the benchmark")
        return bench(args)
    except Failure as e:
        print("FAIL: " + str(e), flush=True)
        return 1


if __name__ == "__main__":
    sys.exit(main())
