#!/usr/bin/env python3
"""The `device` label splits the registered tests in two: `ctest -L device` and `ctest -LE device`
list every test once between them, the GoogleTests that open no OpenCL device (the patterns of
cmake/host_only_tests.cmake) are outside the label and every other GoogleTest inside it. A
host-only GoogleTest is a CTest of its own; a suite's device tests run together as the CTest
`Suite.*` (cmake/write_gtest_ctests.cmake): every GoogleTest runs in exactly one CTest.

    tests/device_labels_test.py --ctest ctest --build build --source .

Whether the tests outside the label really open no device is for `ctest -LE device` to show with
no OpenCL driver to be found (`OCL_ICD_VENDORS=/nonexistent`); docs/architecture.md, Tests.
"""
import argparse
import fnmatch
import json
import os
import re
import subprocess
import sys


def listed(ctest, build, *label_args):
    out = subprocess.run([ctest, "--test-dir", build, "-N", *label_args], check=True, capture_output=True,
                         text=True).stdout
    return re.findall(r"^\s*Test\s+#\d+: (\S+)$", out, re.M)


def host_only_patterns(source):
    text = open(os.path.join(source, "cmake", "host_only_tests.cmake")).read()
    body = re.search(r"set\(SEAMCL_HOST_ONLY_TESTS\b(.*?)\)", text, re.S).group(1)
    lines = (line.split("#", 1)[0].strip() for line in body.splitlines())
    return [word for line in lines for word in line.split()]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ctest", required=True)
    parser.add_argument("--build", required=True)
    parser.add_argument("--source", required=True)
    args = parser.parse_args()

    every = listed(args.ctest, args.build)
    device = listed(args.ctest, args.build, "-L", "device")
    host = listed(args.ctest, args.build, "-LE", "device")
    failures = []
    if len(every) != len(set(every)):
        failures.append("a test is registered twice: %s" % sorted({t for t in every if every.count(t) > 1}))
    if set(device) & set(host):
        failures.append("both labelled device and not: %s" % sorted(set(device) & set(host)))
    if set(device) | set(host) != set(every):
        failures.append("in neither list: %s" % sorted(set(every) - set(device) - set(host)))
    if not device or not host:
        failures.append("%d tests labelled device, %d not: one side is empty" % (len(device), len(host)))

    # The GoogleTests each CTest runs: its command's --gtest_filter, a list of Suite.Test names.
    shown = json.loads(subprocess.run([args.ctest, "--test-dir", args.build, "--show-only=json-v1"], check=True,
                                      capture_output=True, text=True).stdout)
    runs = {}
    for test in shown["tests"]:
        command = test.get("command", [])
        # The two test binaries' CTests (the sanitized fuzz build runs a test of theirs once more).
        if not command or os.path.basename(command[0]) not in ("seamcl_tests", "seamcl_oiio_tests"):
            continue
        filters = [a.split("=", 1)[1] for a in command if a.startswith("--gtest_filter=")]
        if filters:
            runs[test["name"]] = filters[0].split(":")
    # Every GoogleTest the binaries list (but the DISABLED_ reports) runs in some CTest.
    binaries = {test["command"][0] for test in shown["tests"]
                if test.get("command") and os.path.basename(test["command"][0]) in ("seamcl_tests", "seamcl_oiio_tests")}
    listed_gtests = set()
    for binary in binaries:
        suite = ""
        for line in subprocess.run([binary, "--gtest_list_tests"], check=True, capture_output=True, text=True).stdout.splitlines():
            line = line.split("  #")[0]
            if line.endswith(".") and not line.startswith(" "):
                suite = line
            elif line.startswith("  ") and "DISABLED_" not in suite + line:
                listed_gtests.add(suite + line.strip())
    registered = {g for gtests in runs.values() for g in gtests}
    if listed_gtests - registered:
        failures.append("GoogleTests no CTest runs: %s" % sorted(listed_gtests - registered)[:5])
    gtest_device = [g for name in device if name in runs for g in runs[name]]
    gtest_host = [g for name in host if name in runs for g in runs[name]]
    ran = gtest_device + gtest_host
    if len(ran) != len(set(ran)):
        failures.append("a GoogleTest runs in two CTests: %s" % sorted({g for g in ran if ran.count(g) > 1})[:5])
    for name, gtests in runs.items():
        if name in host and gtests != [name]:
            failures.append("%s, outside the device label, runs other than itself: %s" % (name, gtests[:3]))
        if name in device and (not name.endswith(".*") or any(g.split(".")[0] != name[:-2] for g in gtests)):
            failures.append("%s, labelled device, runs tests of other suites or is not named Suite.*: %s" % (name, gtests[:3]))
    if not gtest_device or not gtest_host:
        failures.append("%d GoogleTests in device CTests, %d outside: one side is empty" % (len(gtest_device), len(gtest_host)))

    # Each pattern must match a GoogleTest outside the label (a stale pattern would hide a renamed
    # test's move to `device`) and none inside it.
    patterns = host_only_patterns(args.source)
    for pattern in patterns:
        if not any(fnmatch.fnmatchcase(g, pattern) for g in gtest_host):
            failures.append("cmake/host_only_tests.cmake: %s matches no test outside the device label" % pattern)
        inside = [g for g in gtest_device if fnmatch.fnmatchcase(g, pattern)]
        if inside:
            failures.append("%s matches tests labelled device: %s" % (pattern, inside[:5]))
    # Tests each side must hold whatever the list says: parsers outside, the runtime inside.
    for name in ("SceneJson.*", "OptionTable.BoundsAreEnforcedNamingTheKey", "Ptex.*", "RenderOptions.*"):
        if not any(fnmatch.fnmatchcase(g, name) for g in gtest_host):
            failures.append("%s should be outside the device label" % name)
    for name in ("ClRuntime.PicksADeviceAndListsIt", "Server.*", "KernelVsTwin.*", "Hostile.*"):
        if not any(fnmatch.fnmatchcase(g, name) for g in gtest_device) or any(fnmatch.fnmatchcase(g, name) for g in gtest_host):
            failures.append("%s should all be labelled device" % name)

    print("%d tests: %d labelled device, %d not" % (len(every), len(device), len(host)))
    for failure in failures:
        print("FAIL:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
