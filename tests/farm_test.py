#!/usr/bin/python3
"""scripts/farm on a LocalCluster of 2 workers (Debian's python3-distributed), loopback only:

1. a sharded bench of quad2 (tiny) merges into exactly the unsharded run's per-frame errors,
   temporal pairs, counts, maxima and curves; charts and farm.json are written;
2. a worker killed (SIGKILL) while it runs a part: Dask reschedules the part on the other worker,
   the part has two starts, and the merged result is still the unsharded one;
3. a rerun after one part's file was removed runs that part only (resume);
4. with --flip, each part's FLIP figures pooled into flip.json equal examples/orbit_flip.py's on
   the unsharded run's own images (`bench --images`), and no part leaves images behind.

Usage: farm_test.py --seamcl build/seamcl. Fails (exit 1), never skips, when distributed cannot
be imported: scripts/install-deps installs python3-distributed for /usr/bin/python3.
"""
import argparse
import importlib.machinery
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
FARM = os.path.join(os.path.dirname(HERE), "scripts", "farm")
ORBIT_FLIP = os.path.join(os.path.dirname(HERE), "examples", "orbit_flip.py")

BENCH = ["--scene", "quad2", "--methods", "discard,traverse", "--msaa", "1,4", "--size", "40x36",
         "--frames", "8", "--reference-frames", "3"]
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def load_farm():
    loader = importlib.machinery.SourceFileLoader("farm", FARM)
    spec = importlib.util.spec_from_loader("farm", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


def exact_keys_equal(merged, whole, label):
    """What merges exactly (host/batch/bench_merge.h) is equal; p99 is an upper bound."""
    for key in ("error_frames", "seam_pixels_per_frame", "frames", "options", "shard"):
        check(merged[key] == whole[key], f"{label}: {key} equal")
    per_entry = ("error_per_frame", "nan_pixels_per_frame", "temporal_per_frame", "temporal", "curve", "seam_curve",
                 "nan_pixels")
    for m, w in zip(merged["results"], whole["results"]):
        name = f"{w['method']} x{w['msaa']}"
        for key in per_entry:
            check(m[key] == w[key], f"{label}: {name} {key} equal")
        for key in ("pixels", "seam_pixels", "nan_pixels", "max", "seam_max", "frames"):
            check(m["error"][key] == w["error"][key], f"{label}: {name} error.{key} equal")
        check(abs(m["error"]["mean"] - w["error"]["mean"]) <= 1e-12 * max(1.0, w["error"]["mean"]),
              f"{label}: {name} error.mean equal to rounding")
        check(w["error"]["p99"] <= m["error"]["p99"] <= w["error"]["max"], f"{label}: {name} p99 bound holds")
    check(len(merged["results"]) == len(whole["results"]) == 4, f"{label}: 4 entries")


def farm_args(farm, out, shards, extra=()):
    return farm.parse_args(["--shards", str(shards), "--out", out, "--seamcl", SEAMCL, "--cache",
                            os.path.join(out, "..", "cache"), "--retries", "1", *extra, "--", *BENCH])


def main():
    global SEAMCL
    ap = argparse.ArgumentParser()
    ap.add_argument("--seamcl", required=True)
    SEAMCL = os.path.abspath(ap.parse_args().seamcl)
    from distributed import Client, LocalCluster  # noqa: F401  (fails the test when missing)
    farm = load_farm()
    tmp = tempfile.mkdtemp(prefix="seamcl_farm_test_")
    os.environ["SEAMCL_CACHE_DIR"] = os.path.join(tmp, "cache")
    try:
        # The unsharded run, which also fills the reference cache the parts then share.
        whole = json.loads(subprocess.run([SEAMCL, "bench", *BENCH, "--json"], check=True, timeout=240,
                                          stdout=subprocess.PIPE, stderr=subprocess.DEVNULL).stdout)

        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                               silence_logs=50)
        client = Client(cluster)
        try:
            # 1. Sharded on 2 workers, merged, charted.
            out = os.path.join(tmp, "batch")
            args = farm_args(farm, out, 4)
            farm.prepare_out(args)
            summary = farm.run_batch(client, args, log=lambda line: print("  " + line, flush=True))
            merged = json.load(open(os.path.join(out, "merged.json")))
            exact_keys_equal(merged, whole, "2 workers, 4 parts")
            check(summary["ran"] == [1, 2, 3, 4], f"every part ran ({summary['ran']})")
            check(set(summary["part_worker"].values()) == {"0", "1"}, f"both workers ran parts ({summary['part_worker']})")
            check(os.path.isfile(os.path.join(out, "charts", "pareto.png")), "charts written")
            check(summary["merge_s"] > 0 and json.load(open(os.path.join(out, "farm.json")))["shards"] == 4,
                  "farm.json written")

            # 2. A worker killed while it runs a part.
            out = os.path.join(tmp, "killed")
            args = farm_args(farm, out, 4)
            farm.prepare_out(args)
            result = {}
            runner = threading.Thread(target=lambda: result.update(summary=farm.run_batch(client, args, log=print)))
            runner.start()
            attempts = os.path.join(out, "attempts")
            killed = None
            deadline = time.monotonic() + 60
            while killed is None and time.monotonic() < deadline and runner.is_alive():
                names = sorted(os.listdir(attempts)) if os.path.isdir(attempts) else []
                for name in names:
                    if name.startswith("part-4-of-4."):
                        marker = json.load(open(os.path.join(attempts, name)))
                        os.kill(marker["pid"], signal.SIGKILL)
                        killed = marker
                        break
                time.sleep(0.005)
            runner.join(timeout=180)
            check(killed is not None, "a worker was killed while it ran part 4")
            check(not runner.is_alive() and "summary" in result, "the batch finished after the kill")
            if "summary" in result:
                starts = result["summary"]["attempts"].get("part-4-of-4", 0)
                check(starts >= 2, f"part 4 started again after its worker died ({starts} starts)")
                merged = json.load(open(os.path.join(out, "merged.json")))
                exact_keys_equal(merged, whole, "after a killed worker")

            # 3. Resume: one part's file gone, a rerun runs that part only.
            out = os.path.join(tmp, "batch")
            os.remove(os.path.join(out, "shards", "part-3-of-4.json"))
            args = farm_args(farm, out, 4, ["--no-charts"])
            farm.prepare_out(args)
            summary = farm.run_batch(client, args, log=print)
            check(summary["ran"] == [3] and summary["resumed"] == [1, 2, 4],
                  f"resume ran part 3 only (ran {summary['ran']}, resumed {summary['resumed']})")
            exact_keys_equal(json.load(open(os.path.join(out, "merged.json"))), whole, "resumed")

            # 4. FLIP through the farm against FLIP of the unsharded run's images.
            images = os.path.join(tmp, "images")
            subprocess.run([SEAMCL, "bench", *BENCH, "--images", images, "--json"], check=True, timeout=240,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            folders = sorted(os.listdir(images))
            check(folders == ["frame_000000", "frame_000003", "frame_000006"], f"bench --images: one folder per error frame ({folders})")
            names = sorted(os.listdir(os.path.join(images, "frame_000003")))
            expected = sorted(["reference.png", "seam_mask_msaa1.png", "seam_mask_msaa4.png", "discard_msaa1.png",
                               "discard_msaa4.png", "traverse_msaa1.png", "traverse_msaa4.png"])
            check(names == expected, f"bench --images: the frame's reference, masks and entries ({names})")
            direct = os.path.join(tmp, "direct.flip.json")
            subprocess.run(["/usr/bin/python3", ORBIT_FLIP, "measure", images, "-o", direct, "--jobs", "2"], check=True,
                           timeout=240, stdout=subprocess.DEVNULL)
            direct = json.load(open(direct))
            leftovers_before = {n for n in os.listdir(tempfile.gettempdir()) if n.startswith("seamcl-farm-")}
            out = os.path.join(tmp, "flip")
            args = farm_args(farm, out, 3, ["--flip", "--no-charts"])
            farm.prepare_out(args)
            summary = farm.run_batch(client, args, log=print)
            pooled = json.load(open(os.path.join(out, "flip.json")))
            check(pooled["frames"] == [0, 3, 6], f"flip.json covers the error frames ({pooled['frames']})")
            check(len(summary["part_flip_s"]) == 3, "every part measured its FLIP")
            for p, d in zip(pooled["entries"], direct["entries"]):
                name = f"{d['method']} x{d['msaa']}"
                check((p["method"], p["msaa"], p["frames"], p["pixels"], p["seam_pixels"], p["off_pixels"]) ==
                      (d["method"], d["msaa"], 3, 40 * 36 * 3, d["seam_pixels"], d["off_pixels"]),
                      f"FLIP {name}: entry, frames and pixel counts equal the unsharded run's")
                for key in ("flip_mean", "flip_seam_mean", "flip_off_mean"):
                    check(d[key] is not None and abs(p[key] - d[key]) <= 1e-9 and 0.0 <= d[key] <= 1.0,
                          f"FLIP {name}: {key} {p[key]} equals the unsharded run's {d[key]}")
            by = {(e["method"], e["msaa"]): e for e in pooled["entries"]}
            check(by[("discard", 1)]["flip_seam_mean"] > 0.0, "FLIP sees the 1x seams")
            leftovers = {n for n in os.listdir(tempfile.gettempdir()) if n.startswith("seamcl-farm-")}
            check(leftovers <= leftovers_before, f"no part left its images behind ({sorted(leftovers - leftovers_before)})")
        finally:
            client.close()
            cluster.close()

        # The command line refuses what it sets itself and bad counts, naming them.
        for bad, needle in ((["--shards", "0"], "--shards"), (["--shards", "2", "--", "--shard", "1/2"], "--shard"),
                            (["--shards", "2", "--flip", "--", *BENCH, "--images", "x"], "--images"),
                            (["--shards", "2", "--flip", "--", *BENCH, "--no-errors"], "--no-errors"),
                            (["--shards", "20", "--", *BENCH], "shard: 20 parts of 8 frames")):
            proc = subprocess.run([sys.executable, FARM, "--out", os.path.join(tmp, "bad"), "--seamcl", SEAMCL, *bad],
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=60)
            check(proc.returncode == 2 and needle in proc.stderr, f"farm {' '.join(bad[:3])} refused naming {needle!r}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    if failures:
        print(f"{len(failures)} checks failed", flush=True)
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
