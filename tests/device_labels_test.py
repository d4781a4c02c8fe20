#!/usr/bin/env python3
"""The `device` label splits the registered tests in two: `ctest -L device` and `ctest -LE device`
list every test once between them, the GoogleTests that open no OpenCL device (the patterns of
cmake/host_only_tests.cmake) are outside the label and every other GoogleTest inside it.

    tests/device_labels_test.py --ctest ctest --build build --source .

Whether the tests outside the label really open no device is for `ctest -LE device` to show with
no OpenCL driver to be found (`OCL_ICD_VENDORS=/nonexistent`); docs/architecture.md, Tests.
"""
import argparse
import fnmatch
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

    # A GoogleTest is named Suite.Test; the CTests added by hand are named that way too, so the
    # GoogleTests are told apart by the patterns alone: each must match a test outside the label
    # (a stale pattern would hide a renamed test's move to `device`) and none inside it.
    patterns = host_only_patterns(args.source)
    for pattern in patterns:
        if not any(fnmatch.fnmatchcase(name, pattern) for name in host):
            failures.append("cmake/host_only_tests.cmake: %s matches no test outside the device label" % pattern)
        inside = [name for name in device if fnmatch.fnmatchcase(name, pattern)]
        if inside:
            failures.append("%s matches tests labelled device: %s" % (pattern, inside[:5]))
    # Tests each side must hold whatever the list says: parsers outside, the runtime inside.
    for name in ("SceneJson.*", "OptionTable.BoundsAreEnforcedNamingTheKey", "Ptex.*", "RenderOptions.*"):
        if not any(fnmatch.fnmatchcase(t, name) for t in host):
            failures.append("%s should be outside the device label" % name)
    for name in ("ClRuntime.PicksADeviceAndListsIt", "Server.*", "KernelVsTwin.*", "Hostile.*"):
        if not any(fnmatch.fnmatchcase(t, name) for t in device) or any(fnmatch.fnmatchcase(t, name) for t in host):
            failures.append("%s should all be labelled device" % name)

    print("%d tests: %d labelled device, %d not" % (len(every), len(device), len(host)))
    for failure in failures:
        print("FAIL:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
