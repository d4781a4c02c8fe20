#!/usr/bin/env python3
"""Measures how `seamcl serve` holds up: start-up times, 503 latency under overload, /health
latency behind slow clients, and RSS over a soak of mixed renders and compares. Loopback only;
each check starts its own server on a free port and stops it.

    examples/service_checks.py --seamcl build/seamcl [--checks start,overload,slowloris,soak,protocol,kept]
        [--soak-minutes 10] [--overload-seconds 60] [--memory-bound-mib 2048] [--json]

- start: time until the port answers /health, until the first render of the default scene, and
  until /health says "ready": once with an empty PoCL kernel cache (cold), once warm.
- overload: 32 connections send renders back to back to a server with --threads 2 --queue 8 for
  --overload-seconds; latency of the 503 answers (p50, p99, max) and of the 200s.
- slowloris: 2 x (threads + queue + 4) connections trickle header bytes (httplib's old pool had
  threads + queue + 4 threads); /health latency meanwhile (p50, p99, max).
- soak: renders (built-in and inline scenes, all methods) and compares from 4 clients for the
  given minutes; the server's RSS every 5 s (first, max, last), and its growth after warm-up (the
  first fifth of the run): the median of the last fifth over the median of the second, and the
  largest sample after warm-up over that second fifth's median.
- kept: 18 renders at 64x64 (rgba32f texels, guardband 16), every built-in scene twice, two at a
  time, on a server with --threads 2 and --memory-bound-mib; the RSS after each pair, the steady
  RSS at the end, and /health's memory figures, against the bound.
- protocol: GET /%ff (does the process survive), an unknown method whose body holds a request
  (how many answers), a 16 MiB chunked body (how much is sent before the close, the status),
  /health behind 28 trickling connections, and a second server on the same port.
"""
import argparse
import http.client
import json
import os
import random
import socket
import statistics
import subprocess
import tempfile
import threading
import time


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def percentile(values, p):
    values = sorted(values)
    if not values:
        return float("nan")
    return values[min(len(values) - 1, max(0, int(round(p / 100.0 * (len(values) - 1)))))]


class Server:
    def __init__(self, seamcl, args, env=None):
        self.port = free_port()
        self.started = time.monotonic()
        self.process = subprocess.Popen([seamcl, "serve", "--port", str(self.port)] + args,
                                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)

    def request(self, method, path, body=None, timeout=120):
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=timeout)
        try:
            headers = {"Content-Type": "application/json"} if body is not None else {}
            conn.request(method, path, body=json.dumps(body) if body is not None else None, headers=headers)
            response = conn.getresponse()
            return response.status, response.read()
        finally:
            conn.close()

    def wait(self, predicate, limit=600):
        deadline = time.monotonic() + limit
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise RuntimeError("seamcl serve exited with %s" % self.process.returncode)
            try:
                if predicate():
                    return time.monotonic() - self.started
            except OSError:
                pass
            time.sleep(0.02)
        raise RuntimeError("timed out")

    def health(self):
        status, body = self.request("GET", "/health", timeout=5)
        return json.loads(body) if status == 200 else {}

    def rss_mib(self):
        with open("/proc/%d/status" % self.process.pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
        return float("nan")

    def stop(self):
        self.process.terminate()
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()


def check_start(seamcl):
    out = {}
    cache = tempfile.mkdtemp(prefix="seamcl-pocl-")
    for label in ("cold", "warm"):
        env = dict(os.environ, POCL_CACHE_DIR=cache)
        server = Server(seamcl, ["--threads", "2"], env)
        try:
            listening = server.wait(lambda: server.request("GET", "/health", timeout=2)[0] == 200)
            first_render = server.wait(lambda: server.request("GET", "/v1/render")[0] == 200)
            ready = server.wait(lambda: server.health().get("status") == "ready")
            warm_all = server.wait(lambda: server.health()["warming"]["variants_ready"] >= server.health()["warming"]["variants"])
            out[label] = {"listening_s": round(listening, 3), "first_default_render_s": round(first_render, 3),
                          "ready_s": round(ready, 3), "all_variants_s": round(warm_all, 3)}
        finally:
            server.stop()
    return out


def check_overload(seamcl, clients=32, seconds=60):
    server = Server(seamcl, ["--threads", "2", "--queue", "8", "--quick-start"])
    try:
        server.wait(lambda: server.health().get("status") == "ready")
        results = {"503": [], "200": [], "other": []}
        lock = threading.Lock()
        stop_at = time.monotonic() + seconds

        def client():
            while time.monotonic() < stop_at:
                start = time.monotonic()
                try:
                    status, _ = server.request("GET", "/v1/render?scene=paper&msaa=4&size=480x540")
                except OSError:
                    status = -1
                ms = (time.monotonic() - start) * 1000
                with lock:
                    results[str(status) if status in (200, 503) else "other"].append(ms)
                if status == 503:
                    time.sleep(0.005)

        threads = [threading.Thread(target=client) for _ in range(clients)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        return {"clients": clients, "seconds": seconds,
                **{k: {"count": len(v), "p50_ms": round(percentile(v, 50), 2), "p99_ms": round(percentile(v, 99), 2),
                       "max_ms": round(max(v), 2) if v else float("nan")}
                   for k, v in results.items()}}
    finally:
        server.stop()


def health_behind_slow_clients(server, count, probes, pause):
    """/health latencies (ms) while `count` connections trickle one header byte per probe."""
    slow = []
    try:
        for _ in range(count):
            c = socket.create_connection(("127.0.0.1", server.port), timeout=10)
            c.sendall(b"GET /health HTTP/1.1\r\nHost: x\r\n")
            slow.append(c)
        latencies = []
        for _ in range(probes):
            for c in slow:
                try:
                    c.sendall(b"X")
                except OSError:
                    pass
            start = time.monotonic()
            status, _ = server.request("GET", "/health", timeout=30)
            latencies.append((time.monotonic() - start) * 1000)
            assert status == 200, status
            time.sleep(pause)
        return latencies
    finally:
        for c in slow:
            c.close()


def check_slowloris(seamcl, threads=2, queue=8, probes=40):
    server = Server(seamcl, ["--threads", str(threads), "--queue", str(queue), "--quick-start", "--read-timeout", "60"])
    try:
        server.wait(lambda: server.health().get("status") == "ready")
        count = 2 * (threads + queue + 4)
        latencies = health_behind_slow_clients(server, count, probes, 0.25)
        return {"slow_connections": count, "probes": probes, "health_p50_ms": round(percentile(latencies, 50), 2),
                "health_p99_ms": round(percentile(latencies, 99), 2), "health_max_ms": round(max(latencies), 2)}
    finally:
        server.stop()


def check_soak(seamcl, minutes):
    server = Server(seamcl, ["--threads", "2", "--queue", "8", "--quick-start"])
    try:
        server.wait(lambda: server.health().get("status") == "ready")
        stop_at = time.monotonic() + 60 * minutes
        counts = {}
        lock = threading.Lock()
        methods = json.loads(server.request("GET", "/v1/methods")[1])
        method_names = [m["name"] for m in methods["methods"]]

        def inline_scene(rng):
            faces = []
            for i in range(rng.randint(1, 8)):
                faces.append({"vertices": [4 * i, 4 * i + 1, 4 * i + 2, 4 * i + 3],
                              "texture": {"width": 2 ** rng.randint(0, 7), "height": 2 ** rng.randint(0, 7),
                                          "content": "surface"}})
            positions = []
            for i in range(len(faces)):
                x = float(i)
                positions += [[x, 0, 0], [x + 1, 0, 0], [x + 1, 1, 0], [x, 1, 0]]
            return {"name": "soak", "positions": positions, "faces": faces,
                    "camera": {"eye": [len(faces) / 2, 0.5, 3], "target": [len(faces) / 2, 0.5, 0]}}

        def client(seed):
            rng = random.Random(seed)
            while time.monotonic() < stop_at:
                kind = rng.choice(["render", "render", "render", "inline", "compare"])
                try:
                    if kind == "render":
                        q = "scene=%s&method=%s&msaa=%d&size=%dx%d" % (
                            rng.choice(["paper", "quad2", "cube", "plane"]), rng.choice(method_names),
                            rng.choice([1, 4, 8]), rng.randint(16, 512), rng.randint(16, 512))
                        status, _ = server.request("GET", "/v1/render?" + q)
                    elif kind == "inline":
                        status, _ = server.request("POST", "/v1/render", {"scene": inline_scene(rng), "size": "128x128",
                                                                          "method": rng.choice(method_names)})
                    else:
                        status, _ = server.request("POST", "/v1/compare", {
                            "scene": rng.choice(["paper", "quad2"]), "size": "%dx%d" % (rng.randint(16, 96), rng.randint(16, 96)),
                            "methods": "discard,clamp", "msaa": [1, 4], "repeat": 1, "frame": rng.randint(0, 59), "frames": 60})
                except OSError:
                    status = -1
                with lock:
                    key = "%s %s" % (kind, status)
                    counts[key] = counts.get(key, 0) + 1

        threads = [threading.Thread(target=client, args=(i,)) for i in range(4)]
        for t in threads:
            t.start()
        rss = []
        while any(t.is_alive() for t in threads):
            rss.append(round(server.rss_mib(), 1))
            time.sleep(5)
        for t in threads:
            t.join()
        rss.append(round(server.rss_mib(), 1))
        # RSS swings with the requests in flight, so windows' medians compare, not single samples.
        fifth = max(1, len(rss) // 5)
        warm = statistics.median(rss[fifth:2 * fifth] or rss[-1:])
        end = statistics.median(rss[-fifth:])
        return {"minutes": minutes, "requests": counts,
                "rss_mib": {"first": rss[0], "warm_median": warm, "end_median": end, "max_after_warm": max(rss[fifth:] or rss),
                            "growth_after_warm": round(end / warm - 1, 4),
                            "max_over_warm": round(max(rss[fifth:] or rss) / warm - 1, 4), "samples": rss}}
    finally:
        server.stop()


def check_kept(seamcl, bound_mib):
    server = Server(seamcl, ["--threads", "2", "--queue", "8", "--memory-bound-mib", str(bound_mib)])
    try:
        server.wait(lambda: server.health().get("status") == "ready")
        scenes = json.loads(server.request("GET", "/v1/scenes")[1])
        names = [s["name"] for s in (scenes if isinstance(scenes, list) else scenes["scenes"])]
        queue = [name for name in names for _ in range(2)][:18]
        while len(queue) < 18:
            queue.append(names[len(queue) % len(names)])
        statuses, rss_after_pair = {}, []
        start_rss = round(server.rss_mib(), 1)
        for i in range(0, len(queue), 2):
            pair = queue[i:i + 2]
            answers = [None] * len(pair)

            def render(k):
                answers[k] = server.request("GET", "/v1/render?size=64x64&texels=rgba32f&method=guardband"
                                                   "&guard_band=16&scene=" + pair[k])[0]

            threads = [threading.Thread(target=render, args=(k,)) for k in range(len(pair))]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            for status in answers:
                statuses[str(status)] = statuses.get(str(status), 0) + 1
            rss_after_pair.append(round(server.rss_mib(), 1))
        time.sleep(2)
        memory = server.health().get("memory", {})
        steady = round(server.rss_mib(), 1)
        return {"renders": len(queue), "scenes": names, "statuses": statuses, "bound_mib": bound_mib,
                "rss_mib": {"before": start_rss, "after_each_pair": rss_after_pair, "steady": steady},
                "steady_under_bound": steady < bound_mib,
                "health_memory_mib": {k: round(v / 2 ** 20, 1) for k, v in memory.items() if isinstance(v, (int, float))}}
    finally:
        server.stop()


def read_until_closed(sock, seconds):
    sock.settimeout(seconds)
    out = b""
    try:
        while True:
            data = sock.recv(65536)
            if not data:
                return out
            out += data
    except OSError:
        return out


def check_protocol(seamcl):
    server = Server(seamcl, ["--quick-start"])
    out = {}
    try:
        server.wait(lambda: server.health().get("status") in ("ok", "ready"))
        s = socket.create_connection(("127.0.0.1", server.port), timeout=10)
        s.sendall(b"GET /%ff HTTP/1.1\r\nHost: x\r\n\r\n")
        out["GET /%ff status"] = read_until_closed(s, 3)[9:12].decode(errors="replace")
        time.sleep(0.5)
        out["alive after GET /%ff"] = server.process.poll() is None
        if not out["alive after GET /%ff"]:
            server = Server(seamcl, ["--quick-start"])
            server.wait(lambda: server.health().get("status") in ("ok", "ready"))
        smuggled = b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n"
        s = socket.create_connection(("127.0.0.1", server.port), timeout=10)
        s.sendall(b"FROB /v1/render HTTP/1.1\r\nHost: x\r\nContent-Length: %d\r\n\r\n" % len(smuggled) + smuggled)
        answer = read_until_closed(s, 3)
        out["unknown method + body: answers, first status"] = [answer.count(b"HTTP/1.1 "), answer[9:12].decode()]
        s = socket.create_connection(("127.0.0.1", server.port), timeout=10)
        s.sendall(b"POST /v1/render HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                  b"Transfer-Encoding: chunked\r\n\r\n")
        chunk = b"10000\r\n" + b" " * 65536 + b"\r\n"
        sent = 0
        try:
            for _ in range(256):
                s.sendall(chunk)
                sent += 65536
            s.sendall(b"0\r\n\r\n")
        except OSError:
            pass
        out["16 MiB chunked: MiB sent, status"] = [sent / 2 ** 20, read_until_closed(s, 10)[9:12].decode()]
        out["/health ms behind 28 slow clients"] = [round(ms, 1) for ms in health_behind_slow_clients(server, 28, 6, 1.0)]
        second = subprocess.Popen([seamcl, "serve", "--port", str(server.port), "--quick-start"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            out["second server on the port"] = "exited %d" % second.wait(timeout=25)
        except subprocess.TimeoutExpired:
            out["second server on the port"] = "still running after 25 s (port shared)"
            second.kill()
        return out
    finally:
        server.stop()


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seamcl", default="build/seamcl")
    parser.add_argument("--checks", default="start,overload,slowloris")
    parser.add_argument("--soak-minutes", type=float, default=10.0)
    parser.add_argument("--overload-seconds", type=float, default=60.0)
    parser.add_argument("--memory-bound-mib", type=int, default=2048, help="the kept check's server bound")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    checks = {"start": lambda: check_start(args.seamcl), "overload": lambda: check_overload(args.seamcl, seconds=args.overload_seconds),
              "kept": lambda: check_kept(args.seamcl, args.memory_bound_mib),
              "protocol": lambda: check_protocol(args.seamcl),
              "slowloris": lambda: check_slowloris(args.seamcl), "soak": lambda: check_soak(args.seamcl, args.soak_minutes)}
    out = {}
    for name in args.checks.split(","):
        if name not in checks:
            parser.error("unknown check %r (start, overload, slowloris, soak, protocol, kept)" % name)
        out[name] = checks[name]()
        if not args.json:
            print(name, json.dumps(out[name]), flush=True)
    if args.json:
        print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
