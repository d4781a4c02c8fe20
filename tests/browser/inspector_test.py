#!/usr/bin/env python3
"""The viewer's pixel inspector in a real browser (headless Chromium over the DevTools protocol,
tests/browser/cdp.py) against a live `seamcl serve`:

- the library's debug output for a frame (POST /v1/inspect: the inspect job, host/jobs/inspect_job.h,
  which runs the shading stage's debug variant) names a seam pixel of quad2 under traverse, where
  the lookup reads the edge neighbour's taps;
- a click on that pixel of image A shows, in the inspector's panel, that pixel, and the face and uv
  of its first covered sample equal the library's for that pixel; a row per sample, and the tap
  list names the edge neighbour;
- a click on the same pixel of image B (clamp) shows B's record: the same face and uv, the
  neighbour named with weight 0 (clamp reads none of it);
- the overlays' checkboxes draw, over A and B, exactly the pixels of the library's layers
  (POST /v1/overlays: the seam mask, then the face edges too; on envmap the cube edges too).

Loopback only, bounded in time. Exits 0 on success, 1 on failure.

    tests/browser/inspector_test.py --seamcl build/seamcl [--chromium chromium] [--screenshot FILE]
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
from cdp import Browser, CdpError  # noqa: E402
from viewer_test import Checks, free_port, get, set_controls, wait_idle, wait_ready  # noqa: E402

SIZE = 64
MSAA = 4
BUDGET_S = 280
RENDER_WAIT_S = 150


def inspect(base, method, x, y, window=1):
    status, body = get(base + "/v1/inspect", {"scene": "quad2", "size": "%dx%d" % (SIZE, SIZE), "method": method,
                                              "msaa": MSAA, "x": x, "y": y, "window": window})
    if status != 200:
        raise RuntimeError("POST /v1/inspect: %d %s" % (status, body[:300]))
    return json.loads(body)


def seam_pixel(base):
    """A pixel of quad2 whose traverse lookup reads the edge neighbour's taps, from the library."""
    for y in range(SIZE // 2 - 8, SIZE // 2 + 8, 8):
        for x in range(0, SIZE, 8):
            for pixel in inspect(base, "traverse", x, y, 8)["pixels"]:
                first = next((s for s in pixel["samples"] if s["face"] is not None), None)
                if first and any(t["from"] == "edge" and t["weight"] > 0 for t in first["taps"]):
                    return pixel["x"], pixel["y"]
    raise RuntimeError("no pixel of quad2 reads an edge neighbour")


def click_pixel(page, id_, x, y):
    """Clicks the centre of image pixel (x, y) of the <img> id_ (its content box spans the image)."""
    box = page.eval("(() => { const e = document.getElementById(%s), r = e.getBoundingClientRect(); "
                    "return {left: r.left + e.clientLeft, top: r.top + e.clientTop, w: e.clientWidth, h: e.clientHeight, "
                    "nw: e.naturalWidth, nh: e.naturalHeight}; })()" % json.dumps(id_))
    cx = box["left"] + (x + 0.5) * box["w"] / box["nw"]
    cy = box["top"] + (y + 0.5) * box["h"] / box["nh"]
    page.mouse("mouseMoved", cx, cy)
    page.mouse("mousePressed", cx, cy, 1)
    page.mouse("mouseReleased", cx, cy, 1)


def panel(page):
    return page.eval("(() => { const p = document.getElementById('pixel_inspector'); return Object.assign({}, p.dataset, "
                     "{rows: [...document.querySelectorAll('#pi_samples tbody tr')].map((r) => [...r.cells].map((c) => c.textContent))}); })()")


def run(base, chromium, profile, screenshot, t, deadline):
    x, y = seam_pixel(base)
    print("seam pixel (%d, %d)" % (x, y), flush=True)
    browser = Browser(chromium, profile, width=1300, height=900)
    try:
        page = browser.open(base + "/#scene=quad2&size=%dx%d&scale=4&a=traverse&b=clamp&msaa=%d&zoom=8" % (SIZE, SIZE, MSAA))
        wait_idle(page, min(RENDER_WAIT_S, max(1.0, deadline - time.monotonic())), "the first render")
        for side, id_, method in (("a", "image_a", "traverse"), ("b", "image_b", "clamp")):
            click_pixel(page, id_, x, y)
            page.wait("(() => { const d = document.getElementById('pixel_inspector').dataset; "
                      "return ['shown', 'error'].includes(d.state) && d.side === %s; })()" % json.dumps(side),
                      timeout=min(RENDER_WAIT_S, max(1.0, deadline - time.monotonic())), what="the inspector of " + side)
            shown = panel(page)
            if not t.check(shown.get("state") == "shown", side + ": the inspector shows the pixel",
                           page.eval("document.getElementById('pi_summary').textContent")):
                continue
            library = inspect(base, method, x, y)["pixels"][0]
            first = next(s for s in library["samples"] if s["face"] is not None)
            t.check((int(shown["x"]), int(shown["y"])) == (x, y), side + ": the clicked pixel is inspected",
                    "%s,%s vs %d,%d" % (shown["x"], shown["y"], x, y))
            t.check(int(shown["face"]) == first["face"], side + ": the face is the library's", "%s vs %s" % (shown["face"], first["face"]))
            t.check(float(shown["u"]) == first["uv"][0] and float(shown["v"]) == first["uv"][1],
                    side + ": the uv is the library's", "%s,%s vs %s" % (shown["u"], shown["v"], first["uv"]))
            rows = shown["rows"]
            t.check(len(rows) == MSAA, side + ": a row per sample", str(rows))
            taps = rows[0][-1] if rows else ""
            edge = [line for line in taps.split("\n") if " edge " in line]
            t.check(len(edge) >= 1, side + ": the taps name the edge neighbour", taps)
            weights = [float(line.split()[3]) for line in edge]
            if method == "traverse":
                t.check(any(w > 0 for w in weights), "traverse reads the neighbour's taps", taps)
            else:
                t.check(all(w == 0 for w in weights), "clamp reads none of the neighbour's taps", taps)
            if screenshot and side == "a":
                clip = page.eval("(() => { const a = document.getElementById('view_side').getBoundingClientRect(), "
                                 "p = document.getElementById('pixel_inspector').getBoundingClientRect(); "
                                 "return {x: a.left, y: Math.min(a.top, p.top), width: p.right - a.left, "
                                 "height: Math.max(a.bottom, p.bottom) - Math.min(a.top, p.top), scale: 1}; })()")
                data = page.send("Page.captureScreenshot", {"format": "png", "clip": clip, "captureBeyondViewport": True}, timeout=60)["data"]
                with open(screenshot, "wb") as f:
                    f.write(base64.b64decode(data))
        # Overlays: the seam mask, then the face edges too, over A and B, as the library's layers.
        status, body = get(base + "/v1/overlays", {"scene": "quad2", "size": "%dx%d" % (SIZE, SIZE), "method": "traverse",
                                                   "msaa": MSAA})
        t.check(status == 200, "POST /v1/overlays answers", body[:200])
        layers = json.loads(body)
        flags = base64.b64decode(layers["pixels"])
        bits = layers["layers"]
        for checkbox, mask in (("ov_seam", bits["seam"] | bits["boundary"]),
                               ("ov_edges", bits["seam"] | bits["boundary"] | bits["face_edge"])):
            page.eval("(() => { const e = document.getElementById(%s); e.checked = true; "
                      "e.dispatchEvent(new Event('change')); })()" % json.dumps(checkbox))
            expected = sum(1 for f in flags if f & mask)
            for canvas in ("ov_a", "ov_b"):
                drawn = page.wait("(() => { const c = document.getElementById(%s); return !c.hidden && c.dataset.drawn; })()"
                                  % json.dumps(canvas), timeout=min(RENDER_WAIT_S, max(1.0, deadline - time.monotonic())),
                                  what=canvas + " drawn")
                t.check(int(drawn) == expected, "%s with %s draws the library's layer pixels" % (canvas, checkbox),
                        "%s vs %d" % (drawn, expected))
        t.check(layers["counts"]["seam"] > 0 and layers["counts"]["face_edge"] > 0, "quad2 has seam and face-edge pixels",
                str(layers["counts"]))
        t.check(layers["counts"]["crack"] == 0 and layers["counts"]["cube_edge"] == 0,
                "quad2's crack and cube-edge layers are there, empty", str(layers["counts"]))
        # The cube edges of envmap, drawn with every layer on, as the library's.
        page.eval("(() => { const e = document.getElementById('ov_cube'); e.checked = true; "
                  "e.dispatchEvent(new Event('change')); })()")
        set_controls(page, {"scene": "envmap"})
        wait_idle(page, min(RENDER_WAIT_S, max(1.0, deadline - time.monotonic())), "the envmap render")
        status, body = get(base + "/v1/overlays", {"scene": "envmap", "size": "%dx%d" % (SIZE, SIZE), "method": "traverse",
                                                   "msaa": MSAA})
        t.check(status == 200, "POST /v1/overlays answers for envmap", body[:200])
        envmap = json.loads(body)
        flags = base64.b64decode(envmap["pixels"])
        mask = bits["seam"] | bits["boundary"] | bits["face_edge"] | bits["cube_edge"]
        expected = sum(1 for f in flags if f & mask)
        for canvas in ("ov_a", "ov_b"):
            drawn = page.wait("(() => { const c = document.getElementById(%s); return !c.hidden && c.dataset.cubeEdge === %s "
                              "&& c.dataset.drawn; })()" % (json.dumps(canvas), json.dumps(str(envmap["counts"]["cube_edge"]))),
                              timeout=min(RENDER_WAIT_S, max(1.0, deadline - time.monotonic())), what=canvas + " drawn on envmap")
            t.check(int(drawn) == expected, "%s with the cube edges draws the library's layer pixels" % canvas,
                    "%s vs %d" % (drawn, expected))
        t.check(envmap["counts"]["cube_edge"] > 0 and envmap["counts"]["crack"] == 0,
                "envmap has cube-edge pixels and no crack pixels", str(envmap["counts"]))
        if screenshot:
            clip = page.eval("(() => { const a = document.getElementById('view_side').getBoundingClientRect(); "
                             "return {x: a.left, y: a.top, width: a.width, height: a.height, scale: 1}; })()")
            data = page.send("Page.captureScreenshot", {"format": "png", "clip": clip, "captureBeyondViewport": True},
                             timeout=60)["data"]
            with open(os.path.join(os.path.dirname(screenshot), "viewer-overlays.png"), "wb") as f:
                f.write(base64.b64decode(data))
        t.check(page.errors() == [], "no script errors", str(page.errors()))
    finally:
        browser.close()


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seamcl", required=True)
    parser.add_argument("--chromium", default=shutil.which("chromium") or "chromium")
    parser.add_argument("--screenshot", help="write a screenshot of the images and the inspector here, and one of the "
                        "overlays as viewer-overlays.png beside it")
    args = parser.parse_args()
    start = time.monotonic()
    deadline = start + BUDGET_S
    port = free_port()
    base = "http://127.0.0.1:%d" % port
    cache = tempfile.mkdtemp(prefix="seamcl-inspector-cache-")
    server = subprocess.Popen([args.seamcl, "serve", "--port", str(port), "--quick-start", "--threads", "1"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                              env=dict(os.environ, SEAMCL_CACHE_DIR=cache))
    profile = tempfile.mkdtemp(prefix="seamcl-chromium-")
    t = Checks()
    try:
        wait_ready(base, server, start + 40)
        run(base, args.chromium, profile, args.screenshot, t, deadline)
    except (CdpError, RuntimeError, OSError, ValueError, KeyError, TypeError, StopIteration) as e:
        t.failed.append("aborted: %s: %s" % (type(e).__name__, e))
        print("FAIL: aborted:", type(e).__name__, e, flush=True)
    finally:
        server.terminate()
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            server.kill()
        shutil.rmtree(profile, ignore_errors=True)
        shutil.rmtree(cache, ignore_errors=True)
    print("%d passed, %d failed in %.1f s" % (t.passed, len(t.failed), time.monotonic() - start))
    return 1 if t.failed else 0


if __name__ == "__main__":
    sys.exit(main())
