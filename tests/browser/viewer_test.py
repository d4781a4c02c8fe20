#!/usr/bin/env python3
"""The viewer page in a real browser: headless Chromium loads GET / from a live `seamcl serve`,
the page's script renders through /v1/render, and the <img> must have decoded a PNG of the
default size. Loopback only, bounded in time. Exits 0 on success, 1 on failure.

    tests/browser/viewer_test.py --seamcl build/seamcl [--chromium chromium]
"""
import argparse
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_ready(port, server, deadline):
    while time.monotonic() < deadline:
        if server.poll() is not None:
            raise RuntimeError("server exited with %s" % server.returncode)
        try:
            with urllib.request.urlopen("http://127.0.0.1:%d/health" % port, timeout=2) as r:
                if r.status == 200:
                    return
        except OSError:
            time.sleep(0.3)
    raise RuntimeError("server not ready in time")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seamcl", required=True)
    parser.add_argument("--chromium", default=shutil.which("chromium") or "chromium")
    args = parser.parse_args()

    port = free_port()
    server = subprocess.Popen([args.seamcl, "serve", "--port", str(port), "--quick-start", "--threads", "1"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    profile = tempfile.mkdtemp(prefix="seamcl-chromium-")
    try:
        wait_ready(port, server, time.monotonic() + 120)
        with urllib.request.urlopen("http://127.0.0.1:%d/v1/methods" % port, timeout=10) as r:
            expected_size = json.load(r)["options"]["size"]["default"]
        # Flags from shared/notes/libraries.md: no sandbox (root), no GPU, and nothing that
        # reaches the network; a fresh profile.
        dom = subprocess.run(
            [args.chromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
             "--disable-component-update", "--no-first-run", "--user-data-dir=" + profile,
             "--virtual-time-budget=30000", "--dump-dom", "http://127.0.0.1:%d/" % port],
            capture_output=True, text=True, timeout=120).stdout
        image = re.search(r'<img id="image"[^>]*>', dom)
        status = re.search(r'<div id="status"[^>]*>(.*?)</div>', dom, re.S)
        failures = []
        if not image:
            failures.append("no <img id=image> in the page")
        else:
            size = re.search(r'data-size="(\d+x\d+)"', image.group(0))
            kind = re.search(r'data-type="([^"]*)"', image.group(0))
            if not size or size.group(1) != expected_size:
                failures.append("image decoded as %s, expected %s" % (size.group(1) if size else "nothing", expected_size))
            if not kind or kind.group(1) != "image/png":
                failures.append("image type %s, expected image/png" % (kind.group(1) if kind else "missing"))
        if not status or "render" not in status.group(1) or "error" in status.group(0):
            failures.append("status: %s" % (status.group(0) if status else "missing"))
        for f in failures:
            print("FAIL:", f)
        print("%d passed, %d failed" % (0 if failures else 1, 1 if failures else 0))
        return 1 if failures else 0
    finally:
        server.terminate()
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            server.kill()
        shutil.rmtree(profile, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
