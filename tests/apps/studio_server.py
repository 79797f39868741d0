"""What the studio's browser test (studio_browser.py) and its Selenium-free benchmark (studio_cdp.py)
share: `vitri studio` as a child process, and waiting for a condition. Standard library only."""
import json
import re
import subprocess
import time
import urllib.request


class Failure(Exception):
    pass


class Server:
    """`vitri studio` as a child process on a free port."""

    def __init__(self, vitri, args):
        self.proc = subprocess.Popen([vitri, "studio", "--port", "0"] + args, stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True)
        deadline = time.time() + 120
        while time.time() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                raise Failure("vitri studio exited before serving")
            m = re.search(r"http://([0-9.]+):(\d+)/", line)
            if m:
                self.url = "http://%s:%s" % (m.group(1), m.group(2))
                return
        raise Failure("vitri studio did not print its address")

    def get(self, path):
        with urllib.request.urlopen(self.url + path, timeout=120) as r:
            return json.loads(r.read())

    def stop(self):
        """Stops the server (SIGTERM: a clean shutdown); a sanitizer report or a crash fails the test."""
        self.proc.terminate()
        try:
            rest, _ = self.proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            raise Failure("vitri studio did not stop on SIGTERM")
        if self.proc.returncode != 0:
            raise Failure("vitri studio exited with %d:\n%s" % (self.proc.returncode, rest))


def wait_for(what, fn, timeout=120):
    deadline = time.time() + timeout
    while time.time() < deadline:
        v = fn()
        if v:
            return v
        time.sleep(0.1)
    raise Failure("timed out waiting for " + what)
