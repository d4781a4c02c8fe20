#!/usr/bin/env python3
"""`pip install` of the package into a fresh virtual environment, as a user does, and a render
from that installation equal to this build's. The wheel is built against this build's library
(installed into a temporary prefix: `cmake --install`), with the module alone compiled
(`-C cmake.source-dir=python`), so that CI does not compile the library a second time; a plain
`pip install .` builds the same module over a library it compiles itself (docs/python.md).

    pip_install_check.py --build BUILD_DIR --source SOURCE_DIR"""
import argparse
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

RENDER = ("import sys, numpy, seamcl; r = seamcl.render(scene='quad2', size=(32, 24), method='traverse', msaa=4);"
          "numpy.save(sys.argv[1], r.image); print(seamcl.__file__)")


def run(*args, **kw):
    started = time.monotonic()
    done = subprocess.run([str(a) for a in args], capture_output=True, text=True, **kw)
    if done.returncode != 0:
        sys.exit(f"pip_install_check: {' '.join(map(str, args))} exited {done.returncode}:\n{done.stdout}\n{done.stderr}")
    print(f"pip_install_check: {pathlib.Path(str(args[0])).name} {' '.join(map(str, args[1:3]))} ... "
          f"{time.monotonic() - started:.1f} s")
    return done


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", required=True, type=pathlib.Path)
    parser.add_argument("--source", required=True, type=pathlib.Path)
    args = parser.parse_args()
    args.build, args.source = args.build.resolve(), args.source.resolve()
    with tempfile.TemporaryDirectory(prefix="seamcl-pip-") as tmp:
        tmp = pathlib.Path(tmp)
        run("cmake", "--install", args.build, "--prefix", tmp / "prefix")
        run(sys.executable, "-m", "venv", tmp / "venv")
        python = tmp / "venv" / "bin" / "python"
        run(python, "-m", "pip", "install", "--quiet", "--disable-pip-version-check", args.source,
            "-C", "cmake.source-dir=python", "-C", f"cmake.define.CMAKE_PREFIX_PATH={tmp / 'prefix'}",
            "-C", f"build-dir={tmp / 'wheel-build'}")
        # From the installed package, outside the source tree.
        installed = run(python, "-c", RENDER, tmp / "installed.npy", cwd=tmp).stdout.strip()
        package = pathlib.Path(installed).parent
        if not package.is_relative_to(tmp / "venv"):
            sys.exit(f"pip_install_check: seamcl imported from {installed}, not from the virtual environment")
        for name in ("__init__.pyi", "py.typed", "_options.py", "_errors.py"):
            if not (package / name).is_file():
                sys.exit(f"pip_install_check: the wheel lacks seamcl/{name}")
        if not list(package.glob("_seamcl*.so")):
            sys.exit("pip_install_check: the wheel lacks the module _seamcl")
        env = dict(os.environ, PYTHONPATH=str(args.build / "python"))
        run(sys.executable, "-c", RENDER, tmp / "built.npy", env=env, cwd=tmp)
        a, b = np.load(tmp / "installed.npy"), np.load(tmp / "built.npy")
        if a.shape != (24, 32, 4) or not np.array_equal(a, b) or float(a[..., 3].max()) <= 0:
            sys.exit("pip_install_check: the installed package renders another image than this build's")
    print("pip_install_check: installed into a fresh venv; its render equals this build's")
    return 0


if __name__ == "__main__":
    sys.exit(main())
