#!/usr/bin/python3
"""scripts/replicas: 2 `seamcl serve` replicas behind HAProxy on loopback serve a bounded load
with no failed request while one replica is stopped (SIGTERM) and started again (--respawn);
the balancer sends the restarted replica no render before its /ready says it is warm.

Usage: replicas_test.py --seamcl build/seamcl. Fails, never skips, when haproxy is missing:
scripts/install-deps installs it.
"""
import argparse
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
REPLICAS = os.path.join(os.path.dirname(HERE), "scripts", "replicas")
RENDER = "/v1/render?scene=quad2&size=32x32&msaa=1"
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def free_ports(n):
    """n distinct ports that were free a moment ago (the kernel's ephemeral choice)."""
    sockets = [socket.socket() for _ in range(n)]
    for s in sockets:
        s.bind(("127.0.0.1", 0))
    ports = [s.getsockname()[1] for s in sockets]
    for s in sockets:
        s.close()
    return ports


def consecutive_free_ports(n):
    for _ in range(50):
        base = free_ports(1)[0]
        if base + n > 65535:
            continue
        try:
            held = []
            for p in range(base, base + n):
                s = socket.socket()
                s.bind(("127.0.0.1", p))
                held.append(s)
            for s in held:
                s.close()
            return base
        except OSError:
            for s in held:
                s.close()
    raise RuntimeError("no consecutive free ports")


def states(stats_port):
    """HAProxy's state of each replica, UP or DOWN: "UP 1/2" (up, one failed check of the two that
    take it out) is UP, "DOWN 1/1" (down, one good check of the one that brings it back) DOWN."""
    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{stats_port}/stats;csv", timeout=2) as r:
            lines = r.read().decode().splitlines()
    except OSError:
        return {}
    header = lines[0].lstrip("# ").split(",")
    rows = [dict(zip(header, line.split(","))) for line in lines[1:]]
    return {r["svname"]: r["status"].split(" ")[0] for r in rows
            if r.get("pxname") == "replicas" and r["svname"].startswith("replica")}


def wait_for(predicate, timeout_s, what):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.05)
    check(False, f"{what} within {timeout_s} s")
    return False


class Load:
    """Clients sending renders through HAProxy until stopped, each request counted."""

    def __init__(self, port, clients, max_requests):
        self.url = f"http://127.0.0.1:{port}{RENDER}"
        self.lock = threading.Lock()
        self.ok = 0
        self.failed = []
        self.max_requests = max_requests
        self.stop = threading.Event()
        self.threads = [threading.Thread(target=self.client, daemon=True) for _ in range(clients)]

    def client(self):
        while not self.stop.is_set():
            with self.lock:
                if self.ok + len(self.failed) >= self.max_requests:
                    return
            try:
                with urllib.request.urlopen(self.url, timeout=60) as r:
                    body = r.read()
                    good = r.status == 200 and body.startswith(b"\x89PNG")
                    error = None if good else f"status {r.status}"
            except (urllib.error.URLError, OSError) as e:
                good, error = False, repr(e)
            with self.lock:
                if good:
                    self.ok += 1
                else:
                    self.failed.append(error)

    def count(self):
        with self.lock:
            return self.ok + len(self.failed)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seamcl", required=True)
    seamcl = os.path.abspath(ap.parse_args().seamcl)
    check(shutil.which("haproxy") is not None or os.path.exists("/usr/sbin/haproxy"), "haproxy is installed")
    work = tempfile.mkdtemp(prefix="seamcl_replicas_test_")
    port, stats_port = free_ports(2)
    base = consecutive_free_ports(2)
    proc = subprocess.Popen([sys.executable, REPLICAS, "--replicas", "2", "--port", str(port), "--stats-port",
                             str(stats_port), "--base-port", str(base), "--dir", work, "--seamcl", seamcl,
                             "--check-ms", "200", "--respawn", "--", "--threads", "1", "--quick-start"],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    load = None
    try:
        line = proc.stdout.readline()
        check("2 ready behind" in line, f"replicas started ({line.strip()})")
        with open(os.path.join(work, "replicas.json")) as f:
            first = json.load(f)
        load = Load(port, clients=2, max_requests=4000)
        for t in load.threads:
            t.start()
        wait_for(lambda: load.count() >= 20, 60, "20 requests through HAProxy")

        # Stop replica 0 under load; its supervisor starts it again.
        victim = first["replicas"][0]
        # Counted from the stop, not from HAProxy's DOWN: on a quiet machine the restarted replica
        # is UP again within a few hundred ms of DOWN, while both clients still wait out HAProxy's
        # turn-around before the retry of a request that met the stopped replica.
        before_stop = load.count()
        os.kill(victim["pid"], signal.SIGTERM)
        wait_for(lambda: states(stats_port).get("replica0") == "DOWN", 30, "HAProxy marks replica0 DOWN")

        def restarted():
            with open(os.path.join(work, "replicas.json")) as f:
                return json.load(f)["replicas"][0]["pid"] != victim["pid"]

        wait_for(restarted, 30, "replica0 started again")
        wait_for(lambda: states(stats_port).get("replica0") == "UP", 120, "restarted replica0 UP after warming")
        served_while_out = load.count() - before_stop
        after = load.count()
        wait_for(lambda: load.count() >= after + 20, 60, "20 more requests with both replicas UP")
        load.stop.set()
        for t in load.threads:
            t.join(timeout=70)
        check(not load.failed, f"no failed request of {load.count()} ({load.failed[:3]})")
        # More than the two clients' requests the stopping replica may still have finished.
        check(served_while_out > 2, f"requests served from replica0's stop to its return ({served_while_out})")
        check(states(stats_port) == {"replica0": "UP", "replica1": "UP"}, f"both UP at the end ({states(stats_port)})")

        # The restarted replica got no render before it was warm: in its log after the second
        # start, the first render comes after its "ready:" line.
        with open(os.path.join(work, "replica0.log")) as f:
            lines = f.read().splitlines()
        starts = [i for i, l in enumerate(lines) if l.startswith("seamcl serve: http://")]
        check(len(starts) == 2, f"replica0 started twice ({len(starts)})")
        tail = lines[starts[-1]:] if starts else []
        ready_at = next((i for i, l in enumerate(tail) if l.startswith("ready:")), None)
        render_at = next((i for i, l in enumerate(tail) if l.startswith("GET /v1/render")), None)
        check(ready_at is not None, "restarted replica0 became ready")
        check(render_at is None or (ready_at is not None and render_at > ready_at),
              f"no render reached replica0 before it was warm (ready at line {ready_at}, first render {render_at})")
        check(any(l.startswith("GET /ready 503") for l in tail), "HAProxy saw 503 from /ready while replica0 warmed")
    finally:
        if load:
            load.stop.set()
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
        check(proc.returncode == 0, f"replicas stopped cleanly ({proc.returncode})")
        if failures:  # what a failure in a loaded CI run needs to be read: each replica's log
            for name in ("replica0.log", "replica1.log"):
                try:
                    with open(os.path.join(work, name)) as f:
                        print(f"--- the last lines of {name}:\n" + "".join(f.readlines()[-25:]), flush=True)
                except OSError as e:
                    print(f"--- {name}: {e}", flush=True)
        shutil.rmtree(work, ignore_errors=True)
    if failures:
        print(f"{len(failures)} checks failed", flush=True)
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
