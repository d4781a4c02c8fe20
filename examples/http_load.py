#!/usr/bin/env python3
"""HTTP load for `seamcl serve`: requests/s and p50/p99 latency at several client counts.

Loopback only, bounded in requests and time. Start a server first, e.g.
    build/seamcl serve --port 8080 &
    examples/http_load.py --port 8080 --clients 1,2,8 --requests 40
Each client is a thread with its own keep-alive connection that sends GET /v1/render with the
query below back to back. Next to the latencies it prints the server's own render time (the
X-Seamcl-Render-Ms header, device time from OpenCL profiling events), median over the requests.
"""
import argparse
import http.client
import json
import statistics
import threading
import time

def percentile(values, p):
    values = sorted(values)
    if not values:
        return float("nan")
    k = min(len(values) - 1, max(0, int(round(p / 100.0 * (len(values) - 1)))))
    return values[k]

def run(port, query, clients, requests, time_limit):
    latencies, render_ms, statuses = [], [], {}
    lock = threading.Lock()
    deadline = time.monotonic() + time_limit
    per_client = max(1, requests // clients)

    def client():
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
        for _ in range(per_client):
            if time.monotonic() > deadline:
                break
            start = time.monotonic()
            conn.request("GET", "/v1/render?" + query)
            response = response_body = None
            response = conn.getresponse()
            response_body = response.read()
            elapsed = (time.monotonic() - start) * 1000.0
            with lock:
                statuses[response.status] = statuses.get(response.status, 0) + 1
                if response.status == 200:
                    latencies.append(elapsed)
                    render_ms.append(float(response.getheader("X-Seamcl-Render-Ms")))
            del response_body
        conn.close()

    threads = [threading.Thread(target=client) for _ in range(clients)]
    start = time.monotonic()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    wall = time.monotonic() - start
    return {"clients": clients, "requests": len(latencies), "statuses": statuses,
            "rps": len(latencies) / wall if wall > 0 else 0.0,
            "p50_ms": percentile(latencies, 50), "p99_ms": percentile(latencies, 99),
            "render_ms_median": statistics.median(render_ms) if render_ms else float("nan")}

def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--port", type=int, default=8080)
    parser.add_argument("--query", default="scene=paper&msaa=4&size=256x256")
    parser.add_argument("--clients", default="1,2,8", help="comma list of concurrent client counts")
    parser.add_argument("--requests", type=int, default=40, help="requests per client count (at most 10000)")
    parser.add_argument("--time-limit", type=float, default=60.0, help="seconds per client count (at most 600)")
    parser.add_argument("--warmup", type=int, default=3, help="requests sent first, not counted")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args()
    requests = min(max(args.requests, 1), 10000)
    time_limit = min(max(args.time_limit, 1.0), 600.0)

    run(args.port, args.query, 1, args.warmup, time_limit)
    results = [run(args.port, args.query, int(c), requests, time_limit) for c in args.clients.split(",")]
    if args.json:
        print(json.dumps({"query": args.query, "results": results}, indent=2))
        return
    print(f"GET /v1/render?{args.query}")
    print("| clients | requests | requests/s | p50 ms | p99 ms | render ms (server, median) | statuses |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    for r in results:
        print(f"| {r['clients']} | {r['requests']} | {r['rps']:.1f} | {r['p50_ms']:.1f} | {r['p99_ms']:.1f} | "
              f"{r['render_ms_median']:.1f} | {r['statuses']} |")

if __name__ == "__main__":
    main()
