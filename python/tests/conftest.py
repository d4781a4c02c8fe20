"""Shared by the Python package's tests: the seamcl command of the same build (the CLI the
package's answers are held to), the repository's assets, and a helper that runs the command."""
import json
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
ASSETS = REPO / "tests" / "assets"


def _cli_path():
    given = os.environ.get("SEAMCL_BINARY")
    path = pathlib.Path(given) if given else REPO / "build" / "seamcl"
    if not path.is_file():
        pytest.exit(f"no seamcl command at {path} (set SEAMCL_BINARY)", returncode=1)
    return path


@pytest.fixture(scope="session")
def cli():
    """Runs `seamcl ARGS`; returns the CompletedProcess (text)."""
    path = _cli_path()

    def run(*args, check=True):
        done = subprocess.run([str(path), *map(str, args)], capture_output=True, text=True, timeout=600)
        if check and done.returncode != 0:
            raise AssertionError(f"seamcl {' '.join(map(str, args))} exited {done.returncode}: {done.stderr}")
        return done

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    def run(*args):
        return json.loads(cli(*args).stdout)

    return run
