#!/usr/bin/env python3
"""schemathesis against a live `seamcl serve`: the service must answer every request generated
from its own OpenAPI document (valid and invalid data, methods it does not route) with no 5xx, a
documented status, the documented content type and headers, and a body that matches the
documented schema; invalid data must be refused with a 4xx.

Usage: schemathesis_test.py --seamcl build/seamcl [--max-time 100] [--seed 1] [--warm-all]

Starts `seamcl serve --port <free port> --quick-start --threads 2` (without --quick-start given
--warm-all), waits until GET /health answers 200 and no longer says "starting", runs `python -m
schemathesis.cli run` with this interpreter, prints the figures (requests, 5xx, failures) and
stops the server. Exit 0: nothing found; 1: a failure; 77: schemathesis is not
installed for this interpreter (scripts/install-deps installs it), so CTest reports a skip.
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
import time
import urllib.parse
import urllib.request

# The checks of the run. Left out: positive_data_acceptance (a request the document allows can
# still be refused for what a schema cannot say: width*height*msaa over the server's limit (413),
# frame >= frames, a quad with no area, a busy server (503)), and the checks for authentication
# and stateful resources, which the service does not have.
CHECKS = ",".join([
    "not_a_server_error",
    "status_code_conformance",
    "content_type_conformance",
    "response_headers_conformance",
    "response_schema_conformance",
    "negative_data_rejection",
    "unsupported_method",
    "allow_header_conformance",
])


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for_health(base, server, timeout_s):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if server.poll() is not None:
            raise RuntimeError(f"seamcl serve exited with {server.returncode} before answering /health")
        try:
            with urllib.request.urlopen(base + "/health", timeout=2) as res:
                # A server that warms in the background says "starting" until it is ready.
                if res.status == 200 and json.loads(res.read()).get("status", "ready") != "starting":
                    return
        except OSError:
            pass
        time.sleep(0.2)
    raise RuntimeError(f"no 200 from {base}/health in {timeout_s} s")


def har_figures(paths):
    """Requests made, 5xx answers and requests per operation, from schemathesis's HAR reports."""
    statuses, per_operation, ok_per_operation = [], {}, {}
    for path in paths:
        if not os.path.exists(path):
            continue
        with open(path, encoding="utf-8") as f:
            entries = json.load(f)["log"]["entries"]
        for e in entries:
            statuses.append(e["response"]["status"])
            operation = e["request"]["method"] + " " + urllib.parse.urlsplit(e["request"]["url"]).path
            per_operation[operation] = per_operation.get(operation, 0) + 1
            if 200 <= e["response"]["status"] < 300:
                ok_per_operation[operation] = ok_per_operation.get(operation, 0) + 1
    return len(statuses), sum(1 for s in statuses if s >= 500), per_operation, ok_per_operation


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seamcl", required=True, help="the seamcl executable")
    parser.add_argument("--max-time", type=int, default=100, help="schemathesis time budget in seconds")
    parser.add_argument("--max-examples", type=int, default=100, help="test cases per operation and phase")
    parser.add_argument("--seed", type=int, default=1, help="hypothesis seed, for a reproducible run")
    parser.add_argument("--startup-timeout", type=int, default=120, help="seconds to wait for /health")
    parser.add_argument("--warm-all", action="store_true",
                        help="build every kernel variant before fuzzing (no --quick-start), so that no request of a "
                             "long run waits for a build; give --startup-timeout room for it")
    args = parser.parse_args()

    try:
        import schemathesis  # noqa: F401
    except ImportError:
        print(f"schemathesis is not installed for {sys.executable} (scripts/install-deps installs it): skipped")
        return 77

    port = free_port()
    base = f"http://127.0.0.1:{port}"
    work = tempfile.mkdtemp(prefix="seamcl-schemathesis-")
    env = dict(os.environ, SEAMCL_CACHE_DIR=os.path.join(work, "cache"))
    server_log = open(os.path.join(work, "server.log"), "w+", encoding="utf-8", errors="replace")
    warm = [] if args.warm_all else ["--quick-start"]
    server = subprocess.Popen([args.seamcl, "serve", "--port", str(port), *warm, "--threads", "2"],
                              stdout=server_log, stderr=subprocess.STDOUT, env=env)
    try:
        wait_for_health(base, server, args.startup_timeout)
        # Two runs: a valid compare renders an 8x reference and up to 16 x 10 timed frames (seconds
        # each on a CPU device), so on its own it would spend the whole budget; everything else
        # gets the larger share.
        runs = [("all but POST /v1/compare", ["--exclude-path", "/v1/compare"], args.max_time * 6 // 10),
                ("POST /v1/compare", ["--include-path", "/v1/compare"], args.max_time * 4 // 10)]
        hars, exit_codes = [], []
        started = time.monotonic()
        for label, selection, seconds in runs:
            har = os.path.join(work, f"requests-{len(hars)}.har")
            hars.append(har)
            command = [sys.executable, "-m", "schemathesis.cli", "--no-color", "run", base + "/openapi.json",
                       "--url", base, *selection, "--checks", CHECKS, "--max-time", str(max(seconds, 1)),
                       "--max-examples", str(args.max_examples), "--seed", str(args.seed), "--workers", "2",
                       "--request-timeout", "60", "--generation-database", "none", "--suppress-health-check", "all",
                       "--report", "har", "--report-har-path", har]
            print(f"--- {label}\n$ " + " ".join(command), flush=True)
            exit_codes.append(subprocess.run(command, cwd=work).returncode)
        seconds = time.monotonic() - started
        requests, server_errors, per_operation, ok_per_operation = har_figures(hars)
        print(f"schemathesis: {requests} requests in {seconds:.0f} s, {server_errors} answered 5xx, "
              f"exit codes {exit_codes} (0: no check failed)")
        # Requests per operation and how many got a 2xx: fuzzing that only ever gets refusals
        # never reaches the code behind them.
        for operation, count in sorted(per_operation.items()):
            print(f"  {count:6d}  {ok_per_operation.get(operation, 0):6d} 2xx  {operation}")
        if server.poll() is not None:
            print(f"seamcl serve died during the run (exit code {server.returncode})")
            return 1
        if requests == 0:
            print("no request was made")
            return 1
        return 0 if all(code == 0 for code in exit_codes) and server_errors == 0 else 1
    finally:
        if server.poll() is None:
            server.send_signal(signal.SIGTERM)
            try:
                server.wait(timeout=30)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
        server_log.seek(0)
        lines = server_log.read().splitlines()
        print(f"server log: {len(lines)} lines; last ones:")
        for line in lines[-5:]:
            print("  " + line)
        server_log.close()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
