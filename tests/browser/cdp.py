"""A minimal Chrome DevTools Protocol client over --remote-debugging-pipe (no selenium, no
websockets, nothing to install): Chromium reads commands on fd 3 and writes answers and events on
fd 4, each message JSON ended by a NUL byte. Used by viewer_test.py."""
import base64
import fcntl
import json
import os
import select
import subprocess
import time


class CdpError(RuntimeError):
    pass


class Browser:
    def __init__(self, chromium, profile, width=1400, height=1100):
        to_browser_r, self._to_browser = os.pipe()
        self._from_browser, from_browser_w = os.pipe()
        # The child's ends, moved above 4 first: dup2 onto fds 3 and 4 must neither clobber the
        # other end nor be a no-op (dup2(3, 3) would keep close-on-exec).
        child_r, child_w = fcntl.fcntl(to_browser_r, fcntl.F_DUPFD_CLOEXEC, 10), fcntl.fcntl(from_browser_w, fcntl.F_DUPFD_CLOEXEC, 10)
        os.close(to_browser_r)
        os.close(from_browser_w)

        def pipes():  # in the child: the two pipe ends become fds 3 and 4 (inheritable after dup2)
            os.dup2(child_r, 3)
            os.dup2(child_w, 4)

        # Flags from shared/notes/libraries.md: no sandbox (root), no GPU, nothing that reaches the
        # network, a fresh profile.
        self.process = subprocess.Popen(
            [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
             "--disable-component-update", "--no-first-run", "--user-data-dir=" + profile,
             "--window-size=%d,%d" % (width, height), "--hide-scrollbars", "--remote-debugging-pipe", "about:blank"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            preexec_fn=pipes, close_fds=False)
        os.close(child_r)
        os.close(child_w)
        self._buffer = b""
        self._next_id = 0

    def close(self):
        try:
            self.send("Browser.close", timeout=5)
        except Exception:
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        for fd in (self._to_browser, self._from_browser):
            try:
                os.close(fd)
            except OSError:
                pass

    def _read_message(self, deadline):
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0:
                raise CdpError("no answer from Chromium in time")
            ready, _, _ = select.select([self._from_browser], [], [], left)
            if ready:
                chunk = os.read(self._from_browser, 1 << 20)
                if not chunk:
                    raise CdpError("Chromium closed the pipe (exit %s)" % self.process.poll())
                self._buffer += chunk
        message, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(message)

    def send(self, method, params=None, session=None, timeout=30):
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self._to_browser, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            answer = self._read_message(deadline)
            if answer.get("id") == self._next_id:  # events (no id) are not needed here
                if "error" in answer:
                    raise CdpError("%s: %s" % (method, answer["error"]))
                return answer.get("result", {})

    def open(self, url):
        """A new tab at url; returns a Page."""
        target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        page = Page(self, session, target)
        page.send("Page.enable")
        page.send("Runtime.enable")
        # Uncaught errors and unhandled rejections of the page, for Page.errors().
        page.send("Page.addScriptToEvaluateOnNewDocument", {"source": (
            "window.__errors = []; addEventListener('error', (e) => __errors.push(String(e.message)));"
            "addEventListener('unhandledrejection', (e) => __errors.push('unhandled: ' + String(e.reason)));")})
        page.send("Page.navigate", {"url": url})
        return page


class Page:
    def __init__(self, browser, session, target):
        self.browser, self.session, self.target = browser, session, target

    def send(self, method, params=None, timeout=30):
        return self.browser.send(method, params, session=self.session, timeout=timeout)

    def eval(self, expression, timeout=30):
        """The value of a JavaScript expression (promises awaited), as JSON-decoded Python."""
        result = self.send("Runtime.evaluate", {"expression": expression, "awaitPromise": True, "returnByValue": True},
                           timeout=timeout)
        if "exceptionDetails" in result:
            raise CdpError("%s: %s" % (expression[:80], result["exceptionDetails"].get("exception", {}).get(
                "description", result["exceptionDetails"].get("text"))))
        return result["result"].get("value")

    def wait(self, expression, timeout=30, what=None):
        """Polls until the expression is truthy; returns its value, or raises after timeout s."""
        deadline = time.monotonic() + timeout
        last = None
        while time.monotonic() < deadline:
            try:
                last = self.eval(expression)
            except CdpError as e:  # e.g. the page is still loading
                last = str(e)
            else:
                if last:
                    return last
            time.sleep(0.1)
        raise CdpError("timed out after %g s waiting for %s (last: %r)" % (timeout, what or expression, last))

    def errors(self):
        return self.eval("window.__errors || []")

    def mouse(self, kind, x, y, buttons=0):
        button = "left" if kind != "mouseMoved" or buttons else "none"
        self.send("Input.dispatchMouseEvent", {"type": kind, "x": x, "y": y, "button": button, "buttons": buttons,
                                               "clickCount": 1 if kind != "mouseMoved" else 0})

    def screenshot(self, path):
        data = self.send("Page.captureScreenshot", {"format": "png", "captureBeyondViewport": True}, timeout=60)["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))

    def close(self):
        self.browser.send("Target.closeTarget", {"targetId": self.target})
