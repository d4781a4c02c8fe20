#!/usr/bin/env python3
"""The viewer page in a real browser: headless Chromium, driven over the DevTools protocol
(tests/browser/cdp.py, a pipe; nothing to install), loads GET / from a live `seamcl serve` and
works it through the DOM after the page's scripts ran:

- both images decode as PNGs of the chosen size; the page's heat map equals one computed here from
  the same PNGs (decoded in Python); each image's time is shown split into queue, build, render
  and encode as the server reported it;
- every domain's controls (cube map, displacement) come from the methods document: each in its
  domain's fieldset, a choice listing exactly the option table's values (a domain's method for A
  and for B), bounds as the table's, shown and sent for the scenes the domain acts on only; the
  environment's controls are the OpenAPI document's Environment schema, and a value set renders
  the scene inline (the page shows the server's render of that request); B with another cube
  method than A renders another image; the scene and texture controls list the files of --assets;
- the orbit scrubber: the next frames are fetched ahead, moving the slider shows the server's
  render of that frame;
- changing method A (twice, quickly) while B is shown changes A's image URL to the last choice;
- a permalink opened in a new tab restores every control and the same images;
- dragging the wipe divider and moving the magnifier follow the pointer;
- a compare fills the Figure 5 and speed/error chart data, showing the entries done (polled from
  GET /v1/progress) and its elapsed time as it runs; Figure 5 has log axes (tick labels powers of ten) and its legend outside the
  plot; the speed/error chart is log-log with a min..max bar per point and the Pareto front of
  examples/charts.py; changing the scene clears it; a size over the server's compare limit is
  refused on the page, not compared at another size;
- a permalink restores the compare table and charts from the browser's copy, or runs the compare
  again with a notice (the same errors);
- through a proxy: a 503 overload is retried with a growing backoff and a notice; a 503 past the
  deadline is not retried; cancel stops a long compare on the page at once;
- an error answer ({"error", "field"}) is shown; the reference is used, or said to be unavailable.
- the inspect view fetches the renders as f32: its pixel readout is the f32 answer's floats at that
  pixel; a wheel zoom keeps the pixel under the cursor and zooms A, B and the difference together,
  a drag pans them together; its error statistics (absolute, signed, a dragged rectangle, against
  the reference) equal the ones computed here from the same f32 answers.

Loopback only, bounded in time (a few minutes). Exits 0 on success, 1 on failure.

    tests/browser/viewer_test.py --seamcl build/seamcl [--chromium chromium] [--screenshots DIR]
"""
import argparse
import http.server
import threading
import json
import math
import os
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.parse
import urllib.request
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cdp import Browser, CdpError  # noqa: E402

SIZE = "64x64"
COMPARE_SIZE = "32x32"  # compare renders an 8x reference: keep it small
BUDGET_S = 480  # the whole test, server start included (renders share 2 cores with other tests in CI)
# A wait on anything that renders: on a cold kernel cache under CI's load, a variant that
# --quick-start did not build takes a minute or more, whichever step first asks for it.
RENDER_WAIT_S = 150


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_ready(base, server, deadline):
    """Waits for /health to say the kernels are warm: "ready" (or "ok" from older servers)."""
    last = None
    while time.monotonic() < deadline:
        if server.poll() is not None:
            raise RuntimeError("server exited with %s" % server.returncode)
        try:
            with urllib.request.urlopen(base + "/health", timeout=2) as r:
                last = json.load(r).get("status")
                if last in ("ready", "ok"):
                    return
        except (OSError, ValueError):
            pass
        time.sleep(0.2)
    raise RuntimeError("server not ready in time (last status %r)" % last)


def get(url, body=None):
    request = urllib.request.Request(url, data=None if body is None else json.dumps(body).encode(),
                                     headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(request, timeout=60) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def fetch_f32(url, body=None):
    """An f32 answer: its floats (r, g, b, a per pixel, rows top first), width and height, checked
    against its headers."""
    request = urllib.request.Request(url, data=None if body is None else json.dumps(body).encode(),
                                     headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(request, timeout=60) as r:
        data, width, height = r.read(), int(r.headers["X-Seamcl-Width"]), int(r.headers["X-Seamcl-Height"])
        assert r.headers["Content-Type"] == "application/octet-stream", r.headers["Content-Type"]
    assert len(data) == width * height * 16, "%d bytes for %dx%d" % (len(data), width, height)
    return list(struct.unpack("<%df" % (width * height * 4), data)), width, height


def decode_png_rgb(data):
    """8-bit RGB or RGBA, non-interlaced PNG -> list of (r, g, b) bytes, width, height."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunk = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", chunk)
        elif kind == b"IDAT":
            idat += chunk
    width, height, depth, colour, _, _, interlace = header
    assert depth == 8 and colour in (2, 6) and interlace == 0, "unsupported PNG %s" % (header,)
    bpp = 4 if colour == 6 else 3
    raw, stride, rows, prev = zlib.decompress(idat), width * bpp, [], bytearray(width * bpp)
    for y in range(height):
        kind, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    pixels = [tuple(row[x * bpp:x * bpp + 3]) for row in rows for x in range(width)]
    return pixels, width, height


def srgb_to_linear(c):
    c /= 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def mean_distance(p, q):
    lut = [srgb_to_linear(i) for i in range(256)]
    total = 0.0
    for a, b in zip(p, q):
        total += math.sqrt(sum((lut[a[k]] - lut[b[k]]) ** 2 for k in range(3)))
    return total / len(p)


class Proxy(http.server.ThreadingHTTPServer):
    """In front of seamcl for what the server cannot do on demand: it delays renders of one method
    (answers that arrive late and out of order); refuses renders of one method as an overloaded
    server does (503, field queue, Retry-After: 1) a given number of times, noting when each
    request came; answers every compare as one past the server's deadline (503, field deadline);
    and, where seamcl has no POST /v1/reference yet, answers it with a stand-in (a traverse render
    of the same frame) so the page's reference path runs too."""
    daemon_threads = True

    def __init__(self, upstream):
        self.upstream, self.slow_method, self.fake_reference = upstream, None, False
        self.busy_method, self.busy_left, self.busy_times = None, 0, []
        self.deadline_compares, self.compares, self.hold_compares = False, 0, False
        super().__init__(("127.0.0.1", 0), ProxyHandler)
        threading.Thread(target=self.serve_forever, daemon=True).start()

    @property
    def base(self):
        return "http://127.0.0.1:%d" % self.server_address[1]


class ProxyHandler(http.server.BaseHTTPRequestHandler):
    def log_message(self, *args):
        pass

    def relay(self, method):
        body = self.rfile.read(int(self.headers.get("Content-Length", 0) or 0)) if method == "POST" else None
        path = self.path
        if method == "POST" and path == "/v1/reference" and self.server.fake_reference:
            request = json.loads(body)
            q = {k: request[k] for k in ("scene", "size", "frame", "frames", "tint", "texels", "aniso", "filter") if k in request}
            q["method"] = "traverse"
            path, method, body = "/v1/render?" + urllib.parse.urlencode(q), "GET", None
        query = urllib.parse.parse_qs(urllib.parse.urlparse(path).query)
        if self.server.slow_method and query.get("method") == [self.server.slow_method]:
            time.sleep(2.0)
        if self.server.busy_method and query.get("method") == [self.server.busy_method] and path.startswith("/v1/render"):
            self.server.busy_times.append(time.monotonic())
            if self.server.busy_left > 0:
                self.server.busy_left -= 1
                return self.refuse(503, "queue", "queue: this server's render queue is full; retry later")
        if method == "POST" and path == "/v1/compare":
            self.server.compares += 1
            if self.server.hold_compares:  # a compare that takes long: never reaches seamcl
                time.sleep(3.0)
            if self.server.deadline_compares or self.server.hold_compares:
                return self.refuse(503, "deadline", "deadline: the compare ran past this server's deadline of 1000 ms")
        request = urllib.request.Request(self.server.upstream + path, data=body, method=method,
                                         headers={"Content-Type": self.headers.get("Content-Type", "application/json")})
        try:
            with urllib.request.urlopen(request, timeout=60) as r:
                status, headers, data = r.status, r.headers, r.read()
        except urllib.error.HTTPError as e:
            status, headers, data = e.code, e.headers, e.read()
        try:
            self.send_response(status)
            for k, v in headers.items():
                if k.lower() in ("content-type", "retry-after") or k.lower().startswith("x-seamcl"):
                    self.send_header(k, v)
            if self.path == "/v1/reference" and status == 200:
                self.send_header("X-Seamcl-Reference-Method", "traverse (stand-in)")
            self.send_header("Content-Length", str(len(data)))
            self.end_headers()
            self.wfile.write(data)
        except OSError:  # the page aborted this request
            pass

    def refuse(self, status, field, error):
        data = json.dumps({"error": error, "field": field}).encode()
        self.send_response(status)
        self.send_header("Content-Type", "application/json")
        self.send_header("Retry-After", "1")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)

    def do_GET(self):
        self.relay("GET")

    def do_POST(self):
        self.relay("POST")


class Checks:
    def __init__(self):
        self.passed, self.failed = 0, []

    def check(self, ok, what, detail=""):
        if ok:
            self.passed += 1
        else:
            self.failed.append("%s %s" % (what, detail))
            print("FAIL:", what, detail, flush=True)
        return ok


# JavaScript helpers run in the page.
CONTROL_IDS = ["scene", "size", "frame", "frames", "tint", "method_a", "method_b", "filter", "msaa", "aniso", "shading",
               "texels", "guard_band", "zero_coverage", "reference_method", "reference_msaa", "view", "scale", "zoom",
               "heat_pair", "wipe", "flip_shown", "compare_rates", "repeat"]
READ_CONTROLS = "Object.fromEntries(%s.map((id) => { const e = document.getElementById(id); " \
                "return [id, e.type === 'checkbox' ? e.checked : e.value]; }))" % json.dumps(CONTROL_IDS)


def set_controls(page, values):
    """Sets controls as a user would (each value, then its change event), in one go."""
    page.eval("for (const [id, v] of %s) { const e = document.getElementById(id); "
              "if (e.type === 'checkbox') e.checked = v === true; else e.value = String(v); "
              "e.dispatchEvent(new Event('change')); }" % json.dumps(list(values.items())))


def set_control(page, id_, value):
    set_controls(page, {id_: value})


def wait_idle(page, timeout, what):
    """Waits for the page's renders to finish; an error shown instead is a failure with its text."""
    state = page.wait("['idle', 'error'].includes(document.body.dataset.state) && document.body.dataset.state",
                      timeout=timeout, what=what)
    if state == "error":
        raise CdpError("%s: the page shows an error: %s" % (what, page.eval("document.getElementById('status').textContent")))


def image_info(page, id_):
    return page.eval("(() => { const e = document.getElementById(%s); return {src: e.dataset.src || '', "
                     "size: e.dataset.size || '', type: e.dataset.type || '', complete: e.complete, "
                     "natural: e.naturalWidth + 'x' + e.naturalHeight}; })()" % json.dumps(id_))


def method_of(src):
    return urllib.parse.parse_qs(src.split("?", 1)[-1]).get("method", [""])[0]


def run(base, chromium, profile, shots, t, deadline):
    status, body = get(base + "/v1/methods")
    info = json.loads(body)
    options, limits = info["options"], info.get("limits", {})
    names = [m["name"] for m in info["methods"]]
    a0 = options["method"]["default"]
    others = [n for n in names if n != a0]
    b0 = others[0]
    _, scenes_body = get(base + "/v1/scenes")
    scenes = json.loads(scenes_body)["scenes"]
    assets = json.loads(get(base + "/v1/assets")[1])["assets"]

    def left():
        return max(1.0, deadline - time.monotonic())

    def step(n):
        print("step %d at %.1f s" % (n, time.monotonic() - (deadline - BUDGET_S)), flush=True)

    def shot(page, name):
        if shots:
            page.screenshot(os.path.join(shots, name))

    browser = Browser(chromium, profile)
    try:
        step(1)
        # 1. A permalink with a small size: both images decode at that size.
        page = browser.open(base + "/#size=%s&scale=4&a=%s&b=%s&zoom=8&loupe=32,32" % (SIZE, a0, b0))
        wait_idle(page, min(RENDER_WAIT_S, left()), "the first render")
        for id_ in ("image_a", "image_b"):
            page.wait("document.getElementById(%s).complete" % json.dumps(id_), timeout=5)
            i = image_info(page, id_)
            t.check(i["size"] == SIZE and i["natural"] == SIZE, id_ + " decodes at " + SIZE, str(i))
            t.check(i["type"] == "image/png", id_ + " is a PNG", str(i))
        ia, ib = image_info(page, "image_a"), image_info(page, "image_b")
        t.check(method_of(ia["src"]) == a0 and method_of(ib["src"]) == b0, "A and B show the methods of the permalink",
                "%s | %s" % (ia["src"], ib["src"]))
        status_text = page.eval("document.getElementById('status').textContent")
        t.check("error" not in page.eval("document.getElementById('status').className"), "no error after render",
                status_text)
        # The server's split of each answer's time, shown as it reported it (device time inside
        # the server's wall time).
        for which in ("A", "B"):
            timing = json.loads(page.eval("document.getElementById('status').dataset.timings%s || '{}'" % which))
            parts = ("queue", "build", "render", "encode")
            t.check(set(timing) == set(parts + ("server",)) and all(timing[k] >= 0 for k in timing)
                    and sum(timing[k] for k in parts) <= timing["server"] + 0.01,
                    which + "'s timings split into queue, build, render and encode within the server's time", str(timing))
        t.check(all(k in status_text for k in ("queue ", "build ", "render ", "encode ")), "the status names the timings",
                status_text)

        # Every domain's controls, from the methods document's domains and options (never listed
        # here): each option of a domain in the domain's fieldset, a choice with exactly the
        # table's values (and "none" where leaving it out means something), bounds as the table's.
        domains = info.get("domains", {})
        t.check("cube_method" in domains.get("cube", []) and "displacement_method" in domains.get("displacement", []),
                "the methods document names the cube and displacement domains", str(domains))
        for domain, keys in domains.items():
            for key in keys:
                spec = options[key]
                control = page.eval("(() => { const e = document.getElementById('option_%s'); if (!e) return null; "
                                    "return {fieldset: e.closest('fieldset').id, tag: e.tagName, min: e.min, max: e.max, "
                                    "values: e.tagName === 'SELECT' ? [...e.options].map((o) => o.value) : null}; })()" % key)
                if not t.check(control is not None and control["fieldset"] == "domain_" + domain,
                               "option %s has a control in the %s fieldset" % (key, domain), str(control)):
                    continue
                if "enum" in spec:
                    want = [str(v) for v in spec["enum"]]
                    if "default" not in spec:
                        want = [""] + want
                    t.check(control["values"] == want, "the %s control lists exactly the option table's values" % key,
                            "%r vs %r" % (control["values"], want))
                    if key.endswith("_method"):  # a domain's method: a control for B too
                        b_values = page.eval("[...document.getElementById('option_%s_b').options].map((o) => o.value)" % key)
                        t.check(b_values == want, "the %s control of B lists the same values" % key, str(b_values))
                elif spec.get("type") == "integer":
                    t.check((control["min"], control["max"]) == (str(spec["minimum"]), str(spec["maximum"])),
                            "the %s control has the option's bounds" % key, str(control))
        # A domain's controls are shown for the scenes it acts on (GET /v1/scenes "domains") and
        # its options sent for those only. Switched and back in one script turn: the page's
        # render waits for the controls to settle, so nothing is rendered for the switch.
        for domain, keys in domains.items():
            acting = [sc["name"] for sc in scenes if domain in sc.get("domains", [])]
            other = next((sc["name"] for sc in scenes if domain not in sc.get("domains", [])), None)
            if not t.check(acting and other, "some scenes have the %s domain and some not" % domain, str(scenes)):
                continue
            key = next(k for k in keys if "enum" in options[k])
            pick = str(options[key]["enum"][-1])
            seen = page.eval("""(() => {
                const scene = document.getElementById('scene'), control = document.getElementById('option_%s');
                const was = [scene.value, control.value], out = {};
                for (const name of [%s, %s]) {
                  scene.value = name; scene.dispatchEvent(new Event('change'));
                  control.value = %s; control.dispatchEvent(new Event('change'));
                  out[name] = [getComputedStyle(document.getElementById('domain_%s')).display === 'none',
                               renderParams('x').get('%s')];
                }
                control.value = was[1]; control.dispatchEvent(new Event('change'));
                scene.value = was[0]; scene.dispatchEvent(new Event('change'));
                return out; })()""" % (key, json.dumps(acting[0]), json.dumps(other), json.dumps(pick), domain, key))
            t.check(seen[acting[0]] == [False, pick] and seen[other] == [True, None],
                    "the %s controls show, and %s is sent, for %s only" % (domain, key, acting[0]), str(seen))
        wait_idle(page, min(RENDER_WAIT_S, left()), "the render after the domain checks")

        # The environment of the cube domain's scenes: a control per property of the OpenAPI
        # document's Environment schema; a value set renders the scene as an inline generator
        # scene, POSTed, and the page shows the server's render of exactly that request.
        doc = json.loads(get(base + "/openapi.json")[1])
        env_schema = doc["components"]["schemas"]["Environment"]["properties"]
        env_controls = page.eval("[...document.querySelectorAll('#domain_cube #environment_controls input')].map((e) => e.id)")
        t.check(env_controls == ["env_" + k for k in env_schema], "an environment control per property of the Environment schema",
                "%r vs %r" % (env_controls, list(env_schema)))
        env_scene = next((sc["name"] for sc in scenes if "cube" in sc.get("domains", [])), None)
        cube_key = next((k for k in domains.get("cube", []) if k.endswith("_method")), None)
        if env_scene and "sun_radius" in env_schema and cube_key:
            # B with another cube method than A's (the default): A and B differ on this scene.
            radius = env_schema["sun_radius"]["default"] * 4
            cube_b = next(v for v in options[cube_key]["enum"] if v != options[cube_key]["default"])
            set_controls(page, {"scene": env_scene, "size": COMPARE_SIZE, "env_sun_radius": str(radius),
                                "option_%s_b" % cube_key: cube_b})
            wait_idle(page, min(RENDER_WAIT_S, left()), "the render with an environment set")
            key = page.eval("document.getElementById('image_a').dataset.src")
            sent = json.loads(key.split(" ", 2)[2]) if key.startswith("POST /v1/render ") else {}
            t.check(sent.get("scene") == {"generator": env_scene, "options": {"environment": {"sun_radius": radius}}},
                    "an environment value sends the scene as an inline generator scene", key)
            key_b = page.eval("document.getElementById('image_b').dataset.src")
            sent_b = json.loads(key_b.split(" ", 2)[2]) if key_b.startswith("POST /v1/render ") else {}
            differ = page.eval("shown.A.image.rgba.some((v, i) => v !== shown.B.image.rgba[i])")
            t.check(cube_key not in sent and sent_b.get(cube_key) == cube_b and differ
                    and cube_b in page.eval("document.getElementById('label_b').textContent"),
                    "B renders with its own cube method, A with the default, and their images differ", key_b)
            if sent:
                shown_a = page.eval("Array.from(shown.A.image.rgba)")
                mine, _, _ = decode_png_rgb(get(base + "/v1/render", sent)[1])
                plain, _, _ = decode_png_rgb(get(base + "/v1/render?" + urllib.parse.urlencode(
                    {k: str(v).lower() if isinstance(v, bool) else v for k, v in sent.items() if k != "scene"}
                    | {"scene": env_scene}))[1])
                t.check([tuple(shown_a[4 * i:4 * i + 3]) for i in range(len(mine))] == mine and mine != plain,
                        "the page shows the server's render with that environment (not the scene's own)")
            # The magnifier was at (32, 32) of the 64x64 image: at 32x32 it is back at the centre.
            loupe_text = page.eval("document.getElementById('loupe_text').textContent")
            t.check("(16, 16)" in loupe_text, "the magnifier goes back to the centre when the size changes", loupe_text)
            shot(page, "0-environment.png")
            set_controls(page, {"scene": options["scene"]["default"], "size": SIZE,
                                "env_sun_radius": str(env_schema["sun_radius"]["default"]),
                                "option_%s_b" % cube_key: options[cube_key]["default"]})
            wait_idle(page, min(RENDER_WAIT_S, left()), "the render after the environment check")

        # The assets of --assets: the scene list is the built-in scenes then every asset; the
        # texture list (for a mesh) every .ptx.
        scene_values = page.eval("[...document.getElementById('scene').options].map((o) => o.value)")
        t.check(scene_values == options["scene"]["enum"] + [a["name"] for a in assets] and len(assets) >= 2,
                "the scene control lists the built-in scenes and the --assets files", "%r vs %r" % (scene_values, assets))
        texture_values = page.eval("[...document.getElementById('texture').options].map((o) => o.value)")
        t.check(texture_values == [""] + [a["name"] for a in assets if a["kind"] == "ptex"],
                "the texture control lists the .ptx assets", str(texture_values))

        step(2)
        # 2. The heat map equals the one computed here from the server's own PNGs.
        pa, w, h = decode_png_rgb(get(base + ia["src"])[1])
        pb, _, _ = decode_png_rgb(get(base + ib["src"])[1])
        expected = mean_distance(pa, pb)
        heat = page.eval("({...document.getElementById('heat').dataset})")
        got = float(heat.get("mean", "nan"))
        t.check(heat.get("size") == SIZE and abs(got - expected) <= 1e-6 + 1e-4 * expected,
                "page heat map mean A vs B matches Python", "page %r, python %.6g" % (heat, expected))
        set_control(page, "view", "heat")
        shot(page, "1-heat.png")

        step(3)
        # 3. Side by side with the magnifier over A (a real pointer move).
        set_control(page, "view", "side")
        r = page.eval("(() => { const r = document.getElementById('image_a').getBoundingClientRect(); "
                      "return [r.left, r.top, r.width, r.height]; })()")
        page.mouse("mouseMoved", r[0] + r[2] * (10.5 / w), r[1] + r[3] * (20.5 / h))
        loupe = page.eval("document.getElementById('loupe_text').textContent")
        t.check("(10, 20)" in loupe, "the magnifier follows the pointer", loupe)
        shot(page, "2-side.png")

        step(4)
        # 4. Wipe: dragging the divider moves it and the URL keeps it.
        set_control(page, "view", "wipe")
        r = page.eval("(() => { const r = document.getElementById('wipe_box').getBoundingClientRect(); "
                      "return [r.left, r.top, r.width, r.height]; })()")
        y = r[1] + r[3] / 2
        page.mouse("mousePressed", r[0] + r[2] * 0.6, y, buttons=1)
        page.mouse("mouseMoved", r[0] + r[2] * 0.3, y, buttons=1)
        page.mouse("mouseMoved", r[0] + r[2] * 0.25, y, buttons=1)
        page.mouse("mouseReleased", r[0] + r[2] * 0.25, y, buttons=0)
        try:  # input events reach the page's handlers with the next frame
            page.wait("Math.abs(document.getElementById('wipe').value - 25) <= 2", timeout=3)
        except CdpError:
            pass
        wipe = page.eval("document.getElementById('wipe').value")
        t.check(abs(int(wipe) - 25) <= 2, "dragging the wipe divider moves it", "wipe=%s" % wipe)
        t.check("wipe=" + wipe in page.eval("location.hash"), "the wipe position is in the URL")
        shot(page, "3-wipe.png")

        step(5)
        # 5. Stale state: with B shown (flip view), change A twice quickly; A's image must follow
        # the last choice and the flip view show B until flipped, then the new A.
        set_control(page, "view", "flip")
        set_control(page, "flip_shown", "B")
        before = image_info(page, "image_a")["src"]
        a1, a2 = others[1 % len(others)], others[2 % len(others)] if len(others) > 2 else a0
        set_control(page, "method_a", a1)
        set_control(page, "method_a", a2)
        wait_idle(page, min(RENDER_WAIT_S, left()), "the render after changing A")
        after = image_info(page, "image_a")["src"]
        t.check(method_of(after) == a2 and after != before or (a2 == a0 and after == before),
                "changing A while B is shown updates A's image", "%s -> %s (wanted method %s)" % (before, after, a2))
        t.check(method_of(image_info(page, "flip_image")["src"]) == b0, "the flip view still shows B")
        set_control(page, "flip_shown", "A")
        t.check(image_info(page, "flip_image")["src"] == after, "flipping shows the new A",
                image_info(page, "flip_image")["src"])
        set_control(page, "method_a", a1)
        wait_idle(page, min(RENDER_WAIT_S, left()), 'a render')
        t.check(method_of(image_info(page, "flip_image")["src"]) == a1, "changing A while A is flipped in shows it")

        step(6)
        # 6. An error answer is shown with its field.
        set_control(page, "size", "0x5")
        page.wait("document.body.dataset.state === 'error'", timeout=min(15, left()), what="the error answer")
        status_text = page.eval("document.getElementById('status').textContent")
        t.check("400" in status_text and "size" in status_text, "the error answer is shown with its field", status_text)
        t.check(page.eval("document.getElementById('size').classList.contains('bad')"), "the size control is marked")
        set_control(page, "size", SIZE)
        wait_idle(page, min(RENDER_WAIT_S, left()), 'a render')

        step(7)
        # 7. Permalink round trip: non-default values everywhere, then a new tab at location.href.
        def other(option, current):
            values = [str(v) for v in options[option]["enum"]]
            return next((v for v in values if v != str(current)), str(current))
        orbit_scene = next((s for s in scenes if s.get("orbit") and s["name"] != options["scene"]["default"]),
                           next((s for s in scenes if s.get("orbit")), None))
        wanted = {
            "filter": other("filter", options["filter"]["default"]),
            "msaa": other("msaa", options["msaa"]["default"]),
            "shading": other("shading", options["shading"]["default"]),
            "texels": other("texels", options["texels"]["default"]),
            "zero_coverage": other("zero_coverage", options["zero_coverage"]["default"]),
            "guard_band": str(min(options["guard_band"]["maximum"], options["guard_band"]["default"] + 3)),
            "aniso": str(max(options["aniso"]["minimum"], options["aniso"]["default"] // 2)),
            "method_b": "guardband" if "guardband" in names else b0,
            "tint": True, "view": "wipe", "scale": "2", "zoom": "16", "wipe": "30", "compare_rates": "chosen",
            "repeat": "2",
        }
        if orbit_scene:
            wanted.update({"scene": orbit_scene["name"], "frame": "3", "frames": "12"})
        set_controls(page, wanted)
        wait_idle(page, min(RENDER_WAIT_S, left()), "the render with every option changed")
        before = page.eval(READ_CONTROLS)
        images_before = [image_info(page, i)["src"] for i in ("image_a", "image_b")]
        href = page.eval("location.href")
        t.check(page.eval("document.getElementById('permalink').href") == href, "the permalink link is the URL")
        set_values = {k: before[k] for k in wanted}
        t.check(set_values == {k: (v if isinstance(v, bool) else str(v)) for k, v in wanted.items()},
                "the page took every value", "%r" % set_values)
        page2 = browser.open(href)
        wait_idle(page2, min(RENDER_WAIT_S, left()), "the permalink's render")
        restored = page2.eval(READ_CONTROLS)
        diff = {k: (before[k], restored[k]) for k in before if before[k] != restored[k]}
        t.check(not diff, "the permalink restores every control", "%r" % diff)
        images_after = [image_info(page2, i)["src"] for i in ("image_a", "image_b")]
        t.check(images_after == images_before, "the permalink shows the same images", "%r vs %r" % (images_before, images_after))
        shot(page2, "4-permalink-wipe.png")
        t.check(not page2.errors(), "no script errors in the permalink's page", str(page2.errors()))
        page2.close()

        if orbit_scene:
            # The orbit scrubber: after frame 3 the next frames were fetched ahead; moving the
            # slider to 4 shows frame 4 (the server's render of frame 4, not 3's image again). On a
            # closed object, which every frame of its orbit shows, and a small one (cube).
            scrub_scene = next((sc["name"] for sc in scenes if sc["name"] == "cube"), options["scene"]["default"])
            set_controls(page, {"scene": scrub_scene, "texels": options["texels"]["default"]})
            wait_idle(page, min(RENDER_WAIT_S, left()), "frame 3 of " + scrub_scene)
            src3 = image_info(page, "image_a")["src"]
            page.wait("document.getElementById('scrubber').dataset.ahead === '4,5'", timeout=min(RENDER_WAIT_S, left()),
                      what="frames 4 and 5 fetched ahead")
            scrub = page.eval("(() => { const e = document.getElementById('scrubber'); return [e.min, e.max, e.value, "
                              "document.getElementById('scrub_label').hidden]; })()")
            t.check(scrub == ["0", "11", "3", False], "the scrubber spans the orbit's frames at frame 3", str(scrub))
            page.eval("(() => { const e = document.getElementById('scrubber'); e.value = '4'; "
                      "e.dispatchEvent(new Event('input')); })()")
            page.wait("new URLSearchParams(document.getElementById('image_a').dataset.src.split('?')[1]).get('frame') === '4'",
                      timeout=min(RENDER_WAIT_S, left()), what="frame 4 shown")
            wait_idle(page, min(RENDER_WAIT_S, left()), "the scrubbed frame")
            src4 = image_info(page, "image_a")["src"]
            t.check(page.eval("document.getElementById('frame').value") == "4" and "frame=4" in page.eval("location.hash"),
                    "the scrubber sets the frame and the permalink")
            t.check(page.eval("document.getElementById('status').dataset.aheadA") == "1",
                    "the scrubbed frame was the one fetched ahead")
            p3, _, _ = decode_png_rgb(get(base + src3)[1])
            p4, _, _ = decode_png_rgb(get(base + src4)[1])
            shown4 = page.eval("Array.from(shown.A.image.rgba)")
            t.check("frame=3" in src3 and p3 != p4 and [tuple(shown4[4 * i:4 * i + 3]) for i in range(len(p4))] == p4,
                    "the page shows the server's render of the scrubbed frame, another image than frame 3's", src4)

        step(8)
        # 8. The reference: used if the server offers POST /v1/reference, else said unavailable.
        set_control(page, "view", "heat")
        set_control(page, "heat_pair", "a_ref")
        ref_status, _ = get(base + "/v1/reference", {"scene": page.eval("document.getElementById('scene').value"),
                                                     "size": SIZE})
        if ref_status == 404:
            page.wait("document.getElementById('notice').textContent.includes('reference is unavailable')",
                      timeout=min(15, left()), what="the reference-unavailable notice")
            t.check(page.eval("document.getElementById('heat').dataset.pair") == "ab", "without a reference: A vs B")
        else:
            page.wait("document.getElementById('heat').dataset.pair === 'a_ref'", timeout=min(RENDER_WAIT_S, left()),
                      what="the heat map against the reference")
            t.check(page.eval("document.getElementById('heat').dataset.size") == SIZE, "the reference heat map's size")

        step(9)
        # 9. Compare: at the size shown, all rates, charts filled; a scene change clears them.
        set_controls(page, {"view": "side", "compare_rates": "all", "repeat": "1", "scene": options["scene"]["default"],
                            "frame": "", "tint": False, "shading": options["shading"]["default"],
                            "texels": options["texels"]["default"], "msaa": str(options["msaa"]["default"]),
                            "size": COMPARE_SIZE})
        wait_idle(page, min(RENDER_WAIT_S, left()), 'a render')
        page.eval("document.getElementById('compare').click()")
        # While it runs: the elapsed time and the entries done, as the page shows them.
        seen, until = [], time.monotonic() + min(RENDER_WAIT_S, left())
        while time.monotonic() < until:
            state = page.eval("[document.getElementById('compare').dataset.state, "
                              "{...document.getElementById('progress').dataset}]")
            if state[0] != "running":
                break
            if state[1].get("state") == "running":
                seen.append((int(state[1]["done"]), int(state[1]["total"]), float(state[1]["elapsed"]), state[1].get("detail", "")))
            time.sleep(0.2)
        page.wait("['done', 'error'].includes(document.getElementById('compare').dataset.state)", timeout=5,
                  what="the compare answer")
        data = json.loads(page.eval("document.getElementById('chart_data').textContent"))
        status_text = page.eval("document.getElementById('compare_status').textContent")
        rates = len(options["msaa"]["enum"])
        methods = len({page.eval("document.getElementById('method_a').value"),
                       page.eval("document.getElementById('method_b').value")})
        t.check(data is not None, "compare filled the chart data", status_text)
        if data:
            t.check(data["size"] == COMPARE_SIZE and data["request"]["size"] == COMPARE_SIZE, "compare ran at the size shown",
                    data["size"])
            t.check(len(data["pareto"]) == methods * rates, "speed/error chart has a point per method x MSAA",
                    "%d points" % len(data["pareto"]))
            t.check(all(c["points"] == 41 for c in data["curves"] + data["seam_curves"])
                    and len(data["curves"]) == methods * rates, "Figure 5 curves of 41 points", str(data["curves"]))
            t.check(page.eval("document.getElementById('pareto').dataset.points") == str(methods * rates),
                    "the speed/error canvas drew every point")
        entries = methods * rates
        # The entries done and the job's line come from the server (GET /v1/progress, polled).
        done = [x[0] for x in seen]
        t.check(len(seen) >= 2 and all(x[1] == entries for x in seen) and done == sorted(done)
                and seen[-1][2] > seen[0][2] and any(x[3] for x in seen),
                "the compare's progress shows the server's entries done and line, and its elapsed time grows",
                str(seen[:2] + [x for x in seen if x[3]][:3] + seen[-2:]))
        t.check(page.eval("document.getElementById('progress').textContent").startswith("compared %d entries in " % entries),
                "the compare's time is shown when it ends", page.eval("document.getElementById('progress').textContent"))

        # The charts as the Python ones: Figure 5 with both axes logarithmic (every tick label a
        # power of ten) and the legend right of the plot, not over it; the speed/error chart
        # log-log with a min..max bar per point (the compare answer's), the Pareto front circled.
        def canvas(id_):
            return page.eval("({...document.getElementById(%s).dataset})" % json.dumps(id_))

        def power_of_ten(label):
            return label == "1" or (label.startswith("1e") and label[2:].lstrip("-").isdigit())
        for id_ in ("curve_all", "curve_seam", "pareto"):
            c = canvas(id_)
            plot, legend = json.loads(c.get("plot", "null")), json.loads(c.get("legend", "null"))
            t.check(c.get("xscale") == "log" and c.get("yscale") == "log", id_ + " has log axes", str(c))
            t.check(plot and legend and legend[0] >= plot[2], id_ + "'s legend is outside the plot", "%r %r" % (plot, legend))
        for id_ in ("curve_all", "curve_seam"):
            c = canvas(id_)
            yticks, xticks = json.loads(c["yticks"]), json.loads(c["xticks"])
            t.check(len(yticks) >= 4 and all(map(power_of_ten, yticks)) and yticks[0] == "1e-5" and yticks[-1] == "1",
                    id_ + "'s y axis is logarithmic from 1e-5 (its tick labels powers of ten)", str(yticks))
            t.check(xticks == ["1e-4", "1e-3", "1e-2", "1e-1", "1"], id_ + "'s x axis is logarithmic from 1e-4 to 1", str(xticks))
        if data:
            c = canvas("pareto")
            bars = json.loads(c["bars"])
            want = [[p["method"], p["msaa"], p["ms_min"], p["ms_max"]] for p in data["pareto"]]
            t.check(bars == want and all(b[2] <= p["ms"] <= b[3] for b, p in zip(bars, data["pareto"])),
                    "the speed/error chart has a min..max bar per point", "%r vs %r" % (bars, want))
            pts = [(p["ms"], p["seam_mean"]) for p in data["pareto"]]
            front = sorted((i for i, (x, y) in enumerate(pts) if not any(
                x2 <= x and y2 <= y and (x2 < x or y2 < y) for j, (x2, y2) in enumerate(pts) if j != i)), key=lambda i: pts[i][0])
            want_front = ["%s %dx" % (data["pareto"][i]["method"], data["pareto"][i]["msaa"]) for i in front]
            t.check(json.loads(c["front"]) == want_front, "the chart's Pareto front is examples/charts.py's",
                    "%s vs %r" % (c["front"], want_front))
        shot(page, "5-compare.png")

        # The permalink restores the compare too: from this browser's copy in a new tab (the same
        # rows, not run again), and run again, with a notice, where the browser has no copy.
        def table(p):
            return p.eval("[...document.querySelectorAll('#compare_table tbody tr')].map((r) => "
                          "[...r.cells].map((c) => c.textContent))")
        rows = table(page)
        href = page.eval("location.href")
        t.check("cmp=1" in href and len(rows) == entries, "the permalink says compare results are shown", href)
        page5 = browser.open(href)
        page5.wait("document.getElementById('compare').dataset.state === 'done'", timeout=min(RENDER_WAIT_S, left()),
                   what="the permalink's compare")
        t.check(page5.eval("document.getElementById('compare_status').dataset.source") == "saved" and table(page5) == rows
                and page5.eval("document.getElementById('chart_data').textContent")
                == page.eval("document.getElementById('chart_data').textContent"),
                "the permalink restores the compare table and its charts from the browser's copy",
                page5.eval("document.getElementById('compare_status').textContent"))
        page5.close()
        # Another compare (the chosen rate only) that this browser never ran, pasted into the same
        # tab (its images are at hand): run again, said so.
        page5 = page
        page5.eval("location.hash = %s" % json.dumps(href.split("#", 1)[1].replace("rates=all", "rates=chosen")))
        page5.wait("document.getElementById('compare_status').dataset.source === 'rerun'", timeout=min(RENDER_WAIT_S, left()),
                   what="the permalink's compare run again")
        notice = page5.eval("document.getElementById('compare_status').textContent")
        page5.wait("document.getElementById('compare').dataset.state === 'done'", timeout=min(RENDER_WAIT_S, left()),
                   what="the permalink's compare run again")
        again = table(page5)
        msaa0 = str(options["msaa"]["default"])
        same = [r for r in rows if r[1] == msaa0]
        t.check("running it again" in notice and [r[:6] for r in again] == [r[:6] for r in same],
                "a permalink to a compare the browser has not kept runs it again with a notice, and the same errors",
                "%s: %r vs %r" % (notice, again, same))
        shot(page5, "11-permalink-compare.png")
        scene2 = next((s["name"] for s in scenes if s["name"] != options["scene"]["default"]), None)
        if scene2:
            set_control(page, "scene", scene2)
            t.check(page.eval("document.getElementById('chart_data').textContent") == "null"
                    and page.eval("document.getElementById('charts').hidden"), "a scene change clears compare results")
            wait_idle(page, min(RENDER_WAIT_S, left()), 'a render')

        step(10)
        # 10. Over the compare limit: refused on the page, naming the limit, nothing compared.
        limit = limits.get("max_compare_pixels")
        if limit:
            side = math.isqrt(limit) + 1
            set_control(page, "size", "%dx%d" % (side, side))
            wait_idle(page, min(RENDER_WAIT_S, left()), "the render over the compare limit")
            page.eval("document.getElementById('compare').click()")
            state = page.eval("document.getElementById('compare').dataset.state")
            text = page.eval("document.getElementById('compare_status').textContent")
            t.check(state == "refused" and str(limit) in text and "%dx%d" % (side, side) in text,
                    "a compare over the limit is refused on the page", "%s: %s" % (state, text))
            t.check(page.eval("document.getElementById('chart_data').textContent") == "null", "nothing was compared")
            shot(page, "6-over-limit.png")
        t.check(not page.errors(), "no script errors in the page", str(page.errors()))

        step(11)
        # 11. Through the proxy: an answer for the old method A that arrives after the new one's
        # must not be shown; and the heat map against the reference (a stand-in if seamcl has none).
        proxy = Proxy(base)
        try:
            proxy.fake_reference = ref_status == 404
            page3 = browser.open(proxy.base + "/#size=%s&scale=4&a=%s&b=%s&view=heat&heat=a_ref" % (SIZE, a0, b0))
            wait_idle(page3, min(RENDER_WAIT_S, left()), "the page through the proxy")
            page3.wait("document.getElementById('heat').dataset.pair === 'a_ref'", timeout=min(RENDER_WAIT_S, left()),
                       what="the heat map against the reference")
            label = page3.eval("document.getElementById('label_heat').textContent")
            src = image_info(page3, "image_a")["src"]
            pa, _, _ = decode_png_rgb(get(base + src)[1])
            body = {"scene": options["scene"]["default"], "size": SIZE, "aniso": options["aniso"]["default"],
                    "filter": options["filter"]["default"], "texels": options["texels"]["default"]}
            pr, _, _ = decode_png_rgb(get(proxy.base + "/v1/reference", body)[1])
            expected = mean_distance(pa, pr)
            got = float(page3.eval("document.getElementById('heat').dataset.mean"))
            t.check(abs(got - expected) <= 1e-6 + 1e-4 * expected and "reference: traverse" in label,
                    "the heat map against the reference", "page %.6g, python %.6g; %s" % (got, expected, label))
            shot(page3, "7-heat-reference.png")
            proxy.slow_method = a1
            set_control(page3, "method_a", a1)
            time.sleep(0.5)  # the render for a1 is on its way (slow)
            set_control(page3, "method_a", a2)
            wait_idle(page3, min(RENDER_WAIT_S, left()), "the render of the second A")
            time.sleep(2.2)  # the slow answer for a1 has come (or was aborted) by now
            src = image_info(page3, "image_a")["src"]
            t.check(method_of(src) == a2, "a late answer for the previous A is not shown", src)
            proxy.slow_method = None

            # An overloaded server (503, field queue): A's render is retried after Retry-After,
            # then twice that, with a notice; it then shows.
            proxy.busy_method, proxy.busy_left = a2, 2
            retries_before = int(page3.eval("document.getElementById('retry_notice').dataset.retries || '0'"))
            set_control(page3, "aniso", str(max(options["aniso"]["minimum"], options["aniso"]["default"] // 4)))
            page3.wait("document.getElementById('retry_notice').textContent.includes('retry 1 of')", timeout=10,
                       what="the retry notice")
            wait_idle(page3, min(RENDER_WAIT_S, left()), "the render retried")
            notice = page3.eval("document.getElementById('retry_notice').textContent")
            gaps = [b - a for a, b in zip(proxy.busy_times, proxy.busy_times[1:])]
            t.check(int(page3.eval("document.getElementById('retry_notice').dataset.retries")) - retries_before == 2
                    and "answered after 2 retries" in notice and len(gaps) == 2 and 0.9 <= gaps[0] < 1.9 and gaps[1] >= 1.9,
                    "a 503 overload is retried with a growing backoff and a notice", "%s; gaps %r" % (notice, gaps))
            proxy.busy_method = None

            # A compare past the server's deadline (503, field deadline) is not retried.
            set_control(page3, "size", COMPARE_SIZE)
            wait_idle(page3, min(RENDER_WAIT_S, left()), "a render")
            proxy.deadline_compares, proxy.compares = True, 0
            page3.eval("document.getElementById('compare').click()")
            page3.wait("document.getElementById('compare').dataset.state === 'error'", timeout=10, what="the deadline answer")
            time.sleep(1.5)  # longer than the first backoff (Retry-After: 1)
            text = page3.eval("document.getElementById('compare_status').textContent")
            t.check(proxy.compares == 1 and "deadline" in text and "not retried" in text,
                    "a compare past the deadline is not retried", "%d requests: %s" % (proxy.compares, text))
            proxy.deadline_compares = False
            shot(page3, "12-deadline.png")

            # Cancel: the page stops waiting for a long compare at once and says so.
            proxy.hold_compares = True
            page3.eval("document.getElementById('compare').click()")
            page3.wait("document.getElementById('compare').dataset.state === 'running' && "
                       "!document.getElementById('compare_cancel').hidden", timeout=5, what="the compare running")
            clicked = time.monotonic()
            page3.eval("document.getElementById('compare_cancel').click()")
            page3.wait("document.getElementById('compare').dataset.state === 'cancelled'", timeout=2, what="the cancel")
            text = page3.eval("document.getElementById('compare_status').textContent")
            t.check(time.monotonic() - clicked < 1 and "cancelled" in text
                    and page3.eval("document.getElementById('compare_cancel').hidden"),
                    "cancel stops the compare on the page at once", text)
            proxy.hold_compares = False
            t.check(not page3.errors(), "no script errors through the proxy", str(page3.errors()))
        finally:
            proxy.shutdown()
            proxy.server_close()

        step(12)
        # 12. Inspect: the renders as f32. The pixel readout is the f32 answer's value there; a
        # wheel zoom keeps the pixel under the cursor; the error statistics equal Python's from
        # the same f32 answers.
        page4 = browser.open(base + "/#size=%s&a=%s&b=%s&view=inspect&zoom=0" % (SIZE, a0, b0))
        wait_idle(page4, min(RENDER_WAIT_S, left()), "the inspect view's render")
        page4.wait("document.body.dataset.inspect === 'ready'", timeout=min(RENDER_WAIT_S, left()), what="the inspect view's floats")
        fa, fw, fh = fetch_f32(base + image_info(page4, "image_a")["src"] + "&format=f32")
        fb, _, _ = fetch_f32(base + image_info(page4, "image_b")["src"] + "&format=f32")
        t.check("%dx%d" % (fw, fh) == SIZE, "the f32 answer's size headers", "%dx%d" % (fw, fh))

        def panel(id_):
            return page4.eval("(() => { const c = document.getElementById(%s), r = c.getBoundingClientRect(); "
                              "return {left: r.left + c.clientLeft, top: r.top + c.clientTop, zoom: Number(c.dataset.zoom), ox: Number(c.dataset.ox), "
                              "oy: Number(c.dataset.oy)}; })()" % json.dumps(id_))

        def at_pixel(p, x, y):  # the client position of an image pixel's centre on a panel (300 px, canvas.width)
            return p["left"] + (x + 0.5 - p["ox"]) * p["zoom"], p["top"] + (y + 0.5 - p["oy"]) * p["zoom"]

        def readout():
            return page4.eval("({...document.getElementById('insp_readout').dataset})")

        px, py = 21, 37
        cx, cy = at_pixel(panel("insp_a"), px, py)
        page4.mouse("mouseMoved", cx, cy)
        page4.wait("document.getElementById('insp_readout').dataset.x === '%d'" % px, timeout=3, what="the readout")
        r = readout()
        i = py * fw + px
        t.check((int(r["x"]), int(r["y"])) == (px, py), "the readout names the pixel under the pointer", str(r))
        t.check(json.loads(r["a"]) == fa[4 * i:4 * i + 4] and json.loads(r["b"]) == fb[4 * i:4 * i + 4],
                "the readout is the f32 answers' floats", "%s vs %r / %r" % (r, fa[4 * i:4 * i + 4], fb[4 * i:4 * i + 4]))

        # Wheel in at a point off the pixel centre: the pixel stays under the cursor, and every panel zooms.
        before = panel("insp_a")
        wx, wy = at_pixel(before, px, py)
        wx, wy = wx + 0.3 * before["zoom"], wy - 0.2 * before["zoom"]
        for _ in range(3):
            page4.send("Input.dispatchMouseEvent", {"type": "mouseWheel", "x": wx, "y": wy, "deltaX": 0, "deltaY": -120})
        page4.wait("Number(document.getElementById('insp_a').dataset.zoom) > %r" % (before["zoom"] * 2), timeout=3,
                   what="the wheel zoom")
        after = panel("insp_a")
        under = (math.floor(after["ox"] + (wx - after["left"]) / after["zoom"]),
                 math.floor(after["oy"] + (wy - after["top"]) / after["zoom"]))
        page4.mouse("mouseMoved", wx, wy)
        r = readout()
        t.check(under == (px, py) and (int(r["x"]), int(r["y"])) == (px, py),
                "a wheel zoom keeps the image pixel under the cursor", "zoom %g -> %g, pixel %r, readout (%s, %s)" % (
                    before["zoom"], after["zoom"], under, r.get("x"), r.get("y")))
        b_panel, d_panel = panel("insp_b"), panel("insp_diff")
        t.check(all((q["zoom"], q["ox"], q["oy"]) == (after["zoom"], after["ox"], after["oy"]) for q in (b_panel, d_panel)),
                "the zoom is the same in A, B and the difference", "%r %r %r" % (after, b_panel, d_panel))
        # A drag pans every panel by the pointer's travel (whole pixels: the page may get a
        # pointer position rounded).
        gx, gy = round(wx), round(wy)
        page4.mouse("mousePressed", gx, gy, buttons=1)
        page4.mouse("mouseMoved", gx - 20, gy - 10, buttons=1)
        page4.mouse("mouseMoved", gx - 40, gy - 20, buttons=1)
        page4.mouse("mouseReleased", gx - 40, gy - 20)
        panned = panel("insp_b")
        t.check(abs(panned["ox"] - (after["ox"] + 40 / after["zoom"])) < 1e-9 and
                abs(panned["oy"] - (after["oy"] + 20 / after["zoom"])) < 1e-9, "a drag pans A, B and the difference together",
                "%r -> %r" % (after, panned))
        shot(page4, "8-inspect-zoomed.png")

        # Statistics of the whole image (fit), absolute RGB error A vs B.
        page4.eval("document.getElementById('inspect_fit').click()")

        def stats():
            return page4.eval("({...document.getElementById('insp_stats').dataset})")

        def python_stats(errors):
            values = sorted(e for e in errors if math.isfinite(e))
            n = len(values)
            return {"max": values[-1], "min": values[0], "mean": sum(values) / n, "p99": values[max(0, math.ceil(0.99 * n) - 1)]}

        def close(x, y):
            return abs(x - y) <= 1e-12 + 1e-9 * abs(y)

        def rgb_distance(p, q, k):
            return math.sqrt(sum((p[4 * k + c] - q[4 * k + c]) ** 2 for c in range(3)))

        s = stats()
        abs_errors = [rgb_distance(fa, fb, k) for k in range(fw * fh)]
        want = python_stats(abs_errors)
        t.check(s.get("where") == "visible" and s.get("region") == "0,0,%d,%d" % (fw, fh) and s.get("mode") == "abs"
                and all(close(float(s[k]), want[k]) for k in ("max", "mean", "p99")) and want["max"] > 0,
                "max, mean and p99 of the absolute error A vs B equal Python's from the f32 answers", "page %r, python %r" % (s, want))

        # A shift-dragged rectangle: the statistics of those pixels only.
        p = panel("insp_a")
        x0, y0, x1, y1 = 8, 12, 30, 40
        for kind, (x, y) in (("mousePressed", (x0, y0)), ("mouseMoved", (x1, y1)), ("mouseReleased", (x1, y1))):
            cx, cy = at_pixel(p, x, y)
            page4.send("Input.dispatchMouseEvent", {"type": kind, "x": cx, "y": cy, "button": "left", "modifiers": 8,
                                                    "buttons": 1 if kind != "mouseReleased" else 0, "clickCount": 1})
        s = stats()
        want = python_stats([abs_errors[y * fw + x] for y in range(y0, y1 + 1) for x in range(x0, x1 + 1)])
        t.check(s.get("where") == "selection" and s.get("region") == "%d,%d,%d,%d" % (x0, y0, x1 + 1, y1 + 1)
                and close(float(s["max"]), want["max"]) and close(float(s["mean"]), want["mean"]),
                "a dragged rectangle's statistics equal Python's", "page %r, python %r" % (s, want))
        shot(page4, "9-inspect-selection.png")

        # Signed luminance error, whole image again (a shift-click clears the rectangle).
        cx, cy = at_pixel(p, 5, 5)
        for kind in ("mousePressed", "mouseReleased"):
            page4.send("Input.dispatchMouseEvent", {"type": kind, "x": cx, "y": cy, "button": "left", "modifiers": 8,
                                                    "buttons": 1 if kind == "mousePressed" else 0, "clickCount": 1})
        set_control(page4, "error_mode", "signed")
        page4.wait("document.getElementById('insp_stats').dataset.mode === 'signed'", timeout=5, what="the signed error")
        s = stats()

        def luminance(v, k):
            return 0.2126 * v[4 * k] + 0.7152 * v[4 * k + 1] + 0.0722 * v[4 * k + 2]
        want = python_stats([luminance(fa, k) - luminance(fb, k) for k in range(fw * fh)])
        t.check(s.get("where") == "visible" and close(float(s["min"]), want["min"]) and close(float(s["max"]), want["max"]),
                "the signed error's extremes equal Python's", "page %r, python %r" % (s, want))
        units = page4.eval("document.getElementById('insp_bar').dataset.units")
        t.check("luminance" in units, "the colour bar names its units", units)
        shot(page4, "10-inspect-signed.png")

        # Relative error (over B's RGB magnitude, at least 1e-3), and one channel's absolute error.
        set_control(page4, "error_mode", "relative")
        page4.wait("document.getElementById('insp_stats').dataset.mode === 'relative'", timeout=5, what="the relative error")
        s = stats()
        want = python_stats([rgb_distance(fa, fb, k) / max(1e-3, math.hypot(fb[4 * k], fb[4 * k + 1], fb[4 * k + 2]))
                             for k in range(fw * fh)])
        t.check(close(float(s["max"]), want["max"]) and close(float(s["mean"]), want["mean"]),
                "the relative error equals Python's", "page %r, python %r" % (s, want))
        set_controls(page4, {"error_mode": "abs", "channel": "g"})
        page4.wait("document.getElementById('insp_stats').dataset.channel === 'g' && "
                   "document.getElementById('insp_stats').dataset.mode === 'abs'", timeout=5, what="the green channel")
        s = stats()
        want = python_stats([abs(fa[4 * k + 1] - fb[4 * k + 1]) for k in range(fw * fh)])
        t.check(close(float(s["max"]), want["max"]) and close(float(s["mean"]), want["mean"]),
                "the green channel's absolute error equals Python's", "page %r, python %r" % (s, want))
        set_control(page4, "channel", "rgb")

        # Against the reference (when the server has one): the reference is fetched as f32 too.
        if ref_status != 404:
            set_controls(page4, {"error_mode": "abs", "heat_pair": "a_ref"})
            page4.wait("document.getElementById('insp_stats').dataset.pair === 'a_ref' && "
                       "document.body.dataset.inspect === 'ready'", timeout=min(RENDER_WAIT_S, left()), what="A vs the reference")
            body = {"scene": page4.eval("document.getElementById('scene').value"), "size": SIZE,
                    "aniso": options["aniso"]["default"], "filter": options["filter"]["default"],
                    "texels": options["texels"]["default"], "format": "f32"}
            fr, _, _ = fetch_f32(base + "/v1/reference", body)
            want = python_stats([rgb_distance(fa, fr, k) for k in range(fw * fh)])
            s = stats()
            t.check(close(float(s["max"]), want["max"]) and close(float(s["mean"]), want["mean"]),
                    "the absolute error A vs the reference equals Python's", "page %r, python %r" % (s, want))
        t.check(not page4.errors(), "no script errors in the inspect view", str(page4.errors()))
        page4.close()
    finally:
        browser.close()


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seamcl", required=True)
    parser.add_argument("--chromium", default=shutil.which("chromium") or "chromium")
    parser.add_argument("--screenshots", help="write screenshots of the page here")
    args = parser.parse_args()
    if args.screenshots:
        os.makedirs(args.screenshots, exist_ok=True)

    start = time.monotonic()
    deadline = start + BUDGET_S
    port = free_port()
    base = "http://127.0.0.1:%d" % port
    cache = tempfile.mkdtemp(prefix="seamcl-viewer-cache-")
    # A few small assets: the page lists them (scene and texture controls).
    assets = tempfile.mkdtemp(prefix="seamcl-viewer-assets-")
    for name in ("cube.obj", "black.ptx"):
        shutil.copy(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "assets", "ptex", name), assets)
    server = subprocess.Popen([args.seamcl, "serve", "--port", str(port), "--quick-start", "--threads", "1", "--assets", assets],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                              env=dict(os.environ, SEAMCL_CACHE_DIR=cache))
    profile = tempfile.mkdtemp(prefix="seamcl-chromium-")
    t = Checks()
    try:
        wait_ready(base, server, start + 40)
        run(base, args.chromium, profile, args.screenshots, t, deadline)
    except (CdpError, RuntimeError, OSError, ValueError, KeyError, TypeError) as e:
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
        shutil.rmtree(assets, ignore_errors=True)
    print("%d passed, %d failed in %.1f s" % (t.passed, len(t.failed), time.monotonic() - start))
    return 1 if t.failed else 0


if __name__ == "__main__":
    sys.exit(main())
