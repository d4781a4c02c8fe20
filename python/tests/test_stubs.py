"""The committed stubs (python/seamcl/__init__.pyi) are what the option tables make."""
import importlib.util
import pathlib

import seamcl

_spec = importlib.util.spec_from_file_location("generate_stubs",
                                               pathlib.Path(__file__).resolve().parents[1] / "generate_stubs.py")
generate_stubs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(generate_stubs)


def test_committed_stubs_are_generated_from_the_option_tables():
    assert generate_stubs.STUBS.read_text() == generate_stubs.stubs(), "run python/generate_stubs.py"


def test_stubs_name_every_option_of_both_jobs():
    text = generate_stubs.STUBS.read_text()
    for job in ("render", "compare"):
        for spec in seamcl._options.table(job):
            assert f"    {spec['key']}: " in text, spec["key"]
    assert "method: Literal['clamp', 'black', 'discard', 'traverse', 'traverse-edges', 'guardband']" in text
