"""The option tables of the jobs (host/options/option_table.h), read from the library at run
time: the keywords of render() and compare(), their signatures and docstrings, and the stubs
(python/generate_stubs.py) all come from here, so a new option in a table is a new keyword."""
import functools
import inspect
import json
import os

from . import _seamcl


@functools.lru_cache(maxsize=None)
def table(job: str) -> tuple:
    """The options of `job` ("render" or "compare"), in the table's order: dicts with key, type,
    help, default, absent, choices, integers, minimum, maximum, schema."""
    return tuple(json.loads(_seamcl.option_table(job)))


def keys(job: str) -> set:
    return {spec["key"] for spec in table(job)}


def python_default(spec):
    """The table's default as a Python keyword shows it: a size as (width, height)."""
    value = spec["default"]
    if spec["type"] == "size" and isinstance(value, str):
        width, height = value.split("x")
        return (int(width), int(height))
    return value


def request_value(spec, value):
    """A keyword's value as the JSON the job parses: (w, h) -> "WxH", a list or tuple of items as a
    JSON array; the rest as given (the job checks type and bounds and names the field)."""
    if spec["type"] == "size" and isinstance(value, (tuple, list)) and len(value) == 2:
        return f"{_integer(value[0])}x{_integer(value[1])}"
    if spec["type"] == "list" and isinstance(value, (tuple, list)):
        return [_integer(v) if spec["integers"] else v for v in value]
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if hasattr(value, "item") and callable(value.item) and not isinstance(value, (str, bytes)):
        return value.item()  # a numpy scalar
    return value


def _integer(value):
    try:
        return value.__index__()
    except (AttributeError, TypeError):
        return value


def signature(job: str, own: list) -> inspect.Signature:
    """Keyword-only parameters: the table's options with their defaults, then the front end's own."""
    params = [inspect.Parameter(spec["key"], inspect.Parameter.KEYWORD_ONLY, default=python_default(spec))
              for spec in table(job)]
    return inspect.Signature(params + own)


def doc_lines(job: str) -> str:
    lines = []
    for spec in table(job):
        default = python_default(spec)
        shown = spec["absent"] if default is None and spec["absent"] else repr(default)
        choices = f" One of {', '.join(spec['choices'])}." if spec["choices"] else ""
        lines.append(f"    {spec['key']}: {spec['help']}.{choices} Default: {shown}.")
    return "\n".join(lines)
