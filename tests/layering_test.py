#!/usr/bin/env python3
"""The library's folders depend on each other one way only, and the outside reaches it through
<seamcl/...>. Reads every #include of host/, cli/, server/, python/, bench/, tests/ and examples/:

- a file in host/F/ (or a folder inside it, such as host/pipeline/stages/) includes only host/F/
  and the folders F may depend on (ALLOWED);
- OpenCL headers only in host/cl/, OpenImageIO only in host/io/oiio/ (the module the library loads
  on its first image file), and that module includes nothing of the library but host/io/image_codec.h;
- a public header (listed in CMakeLists.txt) includes no private one;
- outside host/, a public header is included as <seamcl/F/NAME.h>, never by a relative path,
  and cli/, server/, python/ and examples/ include no private header at all.
Prints every violation and exits 1 if there is one."""
import pathlib
import re
import sys

ROOT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[1])
HOST = ROOT / "host"

# Each folder and the folders it may include from (besides itself).
ALLOWED = {
    "core": set(),
    "options": {"core"},
    "cl": {"core"},
    "scene": {"core"},
    "pipeline": {"core", "options", "cl", "scene"},
    "io": {"core", "options", "scene", "pipeline"},
    "eval": {"core", "options", "cl", "scene", "pipeline", "io"},
    "memory": {"core", "options", "cl", "scene", "pipeline", "io", "eval"},
    "assets": {"core", "options", "scene", "pipeline", "io", "memory"},
    "batch": {"core", "options", "cl", "scene", "pipeline", "eval", "memory"},
    "jobs": {"core", "options", "cl", "scene", "pipeline", "io", "eval", "memory", "batch", "assets", "ptexfilter"},
    "ptexfilter": {"core", "options", "cl", "scene", "pipeline", "io", "memory", "assets"},
}
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', re.M)


def public_headers():
    cmake = (ROOT / "CMakeLists.txt").read_text()
    block = re.search(r"set\(SEAMCL_PUBLIC_HEADERS(.*?)\)", cmake, re.S)
    if not block:
        sys.exit("layering_test: SEAMCL_PUBLIC_HEADERS not found in CMakeLists.txt")
    return set(block.group(1).split())


def includes(path):
    return INCLUDE.findall(path.read_text(errors="replace"))


def host_target(kind, name):
    """The host/ path (FOLDER/NAME.h) an include names, or None for anything else."""
    if kind == "<" and name.startswith("seamcl/"):
        rest = name[len("seamcl/"):]
        return None if rest.startswith("kernels/") or rest == "version.h" else rest
    if kind == '"' and (HOST / name).is_file():
        return name
    return None


def main():
    public = public_headers()
    problems = []
    missing = sorted(h for h in public if not (HOST / h).is_file())
    problems += [f"CMakeLists.txt lists a public header that does not exist: host/{h}" for h in missing]
    folders = {p.name for p in HOST.iterdir() if p.is_dir()}
    for extra in sorted(folders - set(ALLOWED)):
        problems.append(f"host/{extra}/ is not in the layering table of tests/layering_test.py")

    for path in sorted(HOST.rglob("*")):
        if path.suffix not in (".h", ".cpp", ".in"):
            continue
        rel = path.relative_to(HOST).as_posix()
        folder = rel.split("/")[0]
        for kind, name in includes(path):
            closing = ">" if kind == "<" else '"'
            where = f"host/{rel}: #include {kind}{name}{closing}"
            if name.startswith("CL/") and folder != "cl":
                problems.append(f"{where}: OpenCL headers belong to host/cl/ only")
            in_module = rel.startswith("io/oiio/")
            if name.startswith("OpenImageIO/") and not in_module:
                problems.append(f"{where}: OpenImageIO only in host/io/oiio/, the module the library loads")
            if in_module and kind == '"' and name != "io/image_codec.h":
                problems.append(f"{where}: the OpenImageIO module links nothing of the library: "
                                "it includes host/io/image_codec.h alone")
            target = host_target(kind, name)
            if target is None:
                continue
            target_folder = target.split("/")[0]
            if target_folder != folder and target_folder not in ALLOWED.get(folder, set()):
                problems.append(f"{where}: host/{folder}/ may not depend on host/{target_folder}/")
            if target in public and kind == '"':
                problems.append(f"{where}: a public header is included as <seamcl/{target}>")
            if target not in public and kind == "<":
                problems.append(f"{where}: host/{target} is private, there is no <seamcl/{target}>")
            if rel in public and target not in public:
                problems.append(f"{where}: a public header includes the private host/{target}")

    for top in ("cli", "server", "python", "bench", "tests", "examples"):
        for path in sorted((ROOT / top).rglob("*")):
            if path.suffix not in (".h", ".cpp"):
                continue
            rel = path.relative_to(ROOT).as_posix()
            for kind, name in includes(path):
                target = host_target(kind, name)
                if target is None:
                    continue
                if target in public and kind == '"':
                    problems.append(f"{rel}: #include \"{name}\": use <seamcl/{target}>")
                if target not in public and top in ("cli", "server", "python", "examples"):
                    problems.append(f"{rel}: #include of host/{target}, which is private to the library and its tests")

    for p in problems:
        print(p)
    print(f"layering: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
