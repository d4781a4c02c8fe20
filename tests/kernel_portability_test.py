#!/usr/bin/env python3
"""The kernels as standard OpenCL C, not as what PoCL happens to accept.

The text of every kernel file in build order (one program holding the five that seamcl builds,
host/cl/kernel_sources.cpp), with the build options of every shading variant (`seamcl warmup
--list`, plus the texel, cube and zero-coverage switches that list leaves at their defaults), is
compiled by clang for the spir64 target as OpenCL C 1.2 and
as OpenCL C 3.0 with every optional 3.0 feature and every extension off (-cl-ext=-all: what any
conformant device must take), warnings as errors. A set of variants that together take every
value of every build switch is then compiled to LLVM IR, translated to SPIR-V (llvm-spirv) and
validated (spirv-val): an intrinsic or construct another vendor's compiler would refuse fails
there. Full translation of every variant would take minutes; the switches only select code paths,
so covering each value once keeps the check to seconds while each path is translated.

Usage: kernel_portability_test.py SEAMCL_BINARY KERNEL_FILE...  (every kernel file, in build order)
Exit 77 (skipped, with the reason) when clang, llvm-spirv or spirv-val is not installed;
scripts/install-deps installs them (clang-14, llvm-spirv-14, spirv-tools).
"""
import concurrent.futures
import os
import re
import shutil
import subprocess
import sys
import tempfile

SKIP = 77


def find_tool(names):
    for name in names:
        path = shutil.which(name)
        if path:
            return path
    return None


def program_text(files):
    # As host/cl/kernel_sources.cpp concatenates them: each file after a #line marker.
    parts = []
    for path in files:
        with open(path, encoding="utf-8") as f:
            parts.append('#line 1 "%s"\n%s\n' % (os.path.basename(path), f.read()))
    return "".join(parts)


def defines(options):
    return dict(re.findall(r"-D(\w+)=(\S+)", options))


def variants(seamcl):
    out = subprocess.run([seamcl, "warmup", "--list"], check=True, capture_output=True, text=True).stdout
    listed = []
    for line in out.splitlines():
        name, options = line.split("\t")
        listed.append((name, options))
    if len(listed) < 2:
        raise SystemExit("seamcl warmup --list gave %d variants" % len(listed))
    # Switches the list leaves at one value (it is the RGBA8, no-environment set): flipped on the
    # first variant, so that their other code paths are compiled too.
    base_name, base = listed[0]
    d = defines(base)
    extra = [(base_name + ", float texels", base.replace("-DSEAMCL_TEXELS_F32=0", "-DSEAMCL_TEXELS_F32=1")),
             (base_name + ", environment", base + " -DSEAMCL_CUBE=1"),
             (base_name + ", zero coverage flipped",
              base.replace("-DSEAMCL_SAMPLER_ZERO_COVERAGE=" + d["SEAMCL_SAMPLER_ZERO_COVERAGE"],
                           "-DSEAMCL_SAMPLER_ZERO_COVERAGE=" + ("1" if d["SEAMCL_SAMPLER_ZERO_COVERAGE"] == "0" else "0")))]
    for name, options in extra:
        if options == base:
            raise SystemExit("could not flip a switch for '%s': the build options changed form: %s" % (name, base))
    return listed + extra


def covering(all_variants):
    """Greedy: variants until every (switch, value) of the set appears in one (the switch absent counts)."""
    def pairs(options):
        d = defines(options)
        for flag in ("SEAMCL_SEAM_MASK", "SEAMCL_CUBE"):
            d.setdefault(flag, "absent")
        return set(d.items())

    wanted = set().union(*(pairs(o) for _, o in all_variants))
    chosen = []
    while wanted:
        best = max(all_variants, key=lambda v: len(pairs(v[1]) & wanted))
        chosen.append(best)
        wanted -= pairs(best[1])
    return chosen


def run(cmd):
    result = subprocess.run(cmd, capture_output=True, text=True)
    return result.returncode, (result.stdout + result.stderr).strip()


STANDARDS = {
    # -cl-std: (clang flags, SPIR-V version cap, spirv-val environment)
    "CL1.2": (["-cl-std=CL1.2"], "1.0", "opencl1.2"),
    "CL3.0": (["-cl-std=CL3.0"], "1.2", "opencl2.2"),
}


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        return 2
    seamcl, files = sys.argv[1], sys.argv[2:]
    clang = find_tool(["clang-14", "clang"])
    translator = find_tool(["llvm-spirv-14", "llvm-spirv"])
    validator = find_tool(["spirv-val"])
    missing = [n for n, t in (("clang-14", clang), ("llvm-spirv-14", translator), ("spirv-val (spirv-tools)", validator)) if not t]
    if missing:
        print("SKIPPED: %s not installed (scripts/install-deps installs them)" % ", ".join(missing))
        return SKIP

    all_variants = variants(seamcl)
    translated = covering(all_variants)
    with tempfile.TemporaryDirectory(prefix="seamcl-spirv-") as tmp:
        source = os.path.join(tmp, "program.cl")
        with open(source, "w", encoding="utf-8") as f:
            f.write(program_text(files))
        common = [clang, "-x", "cl", "-target", "spir64", "-Xclang", "-finclude-default-header",
                  "-Xclang", "-cl-ext=-all", "-Werror", "-I", tmp]

        def syntax(job):
            (name, options), std = job
            code, text = run(common + STANDARDS[std][0] + ["-fsyntax-only"] + options.split() + [source])
            return ("%s, %s: compile" % (name, std), code, text)

        def spirv(job):
            (name, options), std = job
            flags, version, env = STANDARDS[std]
            stem = os.path.join(tmp, "v%d-%s" % (abs(hash((name, std))), std))
            code, text = run(common + flags + ["-O0", "-emit-llvm", "-c", "-o", stem + ".bc"] + options.split() + [source])
            if code == 0:
                code, text = run([translator, "--spirv-max-version=" + version, stem + ".bc", "-o", stem + ".spv"])
            if code == 0:
                code, text = run([validator, "--target-env", env, stem + ".spv"])
            return ("%s, %s: SPIR-V %s for %s" % (name, std, version, env), code, text)

        jobs = [(syntax, (v, std)) for v in all_variants for std in STANDARDS]
        jobs += [(spirv, (v, std)) for v in translated for std in STANDARDS]
        failures = []
        with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
            for label, code, text in pool.map(lambda j: j[0](j[1]), jobs):
                if code != 0:
                    failures.append("%s failed:\n%s" % (label, text[:4000]))
    print("%d variants compiled as OpenCL C 1.2 and 3.0; %d of them (every switch value) translated to SPIR-V and "
          "validated" % (len(all_variants), len(translated)))
    for failure in failures:
        print(failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
