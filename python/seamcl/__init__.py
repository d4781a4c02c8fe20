"""seamcl in Python: the render and compare jobs of the library, with images as numpy arrays.

    import seamcl
    r = seamcl.render(scene="quad2", size=(64, 64), method="discard", msaa=4)
    r.image          # float32 (64, 64, 4), linear RGBA, row 0 at the top
    r.info           # the dict `seamcl render --json` prints

Every option of the jobs' option tables is a keyword, with the same name, default and errors
as the command line's flag (--guard-band is guard_band) and the service's JSON key. See
docs/python.md."""
import json
import inspect
from dataclasses import dataclass, field
from typing import Callable, Dict, List, Optional, Tuple

import numpy as np

from . import _options, _seamcl
from ._errors import Cancelled, InputError, OverBudgetError

__all__ = ["render", "compare", "Scene", "devices", "scenes", "RenderResult", "CompareResult",
           "InputError", "OverBudgetError", "Cancelled", "__version__"]
__version__ = _seamcl.version
_seamcl._bind_errors(InputError, OverBudgetError, Cancelled)


class Scene:
    """A scene to render: a built-in name, a scene JSON file, an .obj quad mesh (with a .ptx of its
    faces' textures) or a .ptx that holds its mesh. Made, it has been read once, so a bad file is
    refused here (InputError naming scene or texture); each render reads it again as the command
    line does."""

    def __init__(self, scene: str, texture: Optional[str] = None):
        for name, value in (("scene", scene), ("texture", texture)):
            if value is not None and not isinstance(value, str):
                value = getattr(value, "__fspath__", lambda: value)()
                if not isinstance(value, str):
                    raise InputError(f"{name}: must be a path or a name, got {value!r}", name)
                if name == "scene":
                    scene = value
                else:
                    texture = value
        self.scene = scene
        self.texture = texture or ""
        self.info = json.loads(_seamcl.describe_scene(self.scene, self.texture))

    @classmethod
    def from_files(cls, mesh, texture=None) -> "Scene":
        """An .obj mesh and the .ptx whose face i textures its face i (or a scene JSON file, or
        a .ptx that carries its mesh, alone)."""
        return cls(mesh, texture)

    @classmethod
    def builtin(cls, name: str) -> "Scene":
        return cls(name)

    @property
    def name(self) -> str:
        return self.info["name"]

    @property
    def faces(self) -> int:
        return self.info["faces"]

    def __repr__(self):
        texture = f", texture={self.texture!r}" if self.texture else ""
        return f"Scene({self.scene!r}{texture}: {self.faces} faces)"


@dataclass
class RenderResult:
    image: np.ndarray  # float32 (height, width, 4), linear RGBA, viewing the renderer's buffer
    info: dict         # `seamcl render --json`
    _buffer_address: int = field(default=0, repr=False)


@dataclass
class CompareResult:
    info: dict                                    # `seamcl compare --json`
    results: List[dict]                           # info["results"]: one per method x msaa
    images: Dict[Tuple[str, int], np.ndarray]     # (method, msaa) -> float32 (H, W, 4); images=True
    error_maps: Dict[Tuple[str, int], np.ndarray]  # (method, msaa) -> float32 (H, W) distance to the reference, NaN where non-finite
    reference: Optional[np.ndarray]               # the first reference, float32 (H, W, 4)
    references: Dict[str, np.ndarray]             # every reference by name (paper, box, analytic, seamless_msaaN)
    seam_masks: Dict[int, np.ndarray]             # msaa -> uint8 (H, W): 1 seam, 2 mesh boundary, 0 elsewhere


def _device(device: Optional[str]) -> str:
    if device is None:
        return ""
    if not isinstance(device, str) or not device:
        raise InputError("device: must not be empty (leave out device for $SEAMCL_DEVICE, else the first GPU, "
                         "else the first CPU)", "device")
    return device


def _request(job: str, options: dict) -> str:
    """The keywords given as the job's JSON request (only those given: a job's default applies to
    the rest, and some options mean something only when given). The job checks every value."""
    request = {}
    specs = {spec["key"]: spec for spec in _options.table(job)}
    for key, value in options.items():
        if key == "scene" and isinstance(value, Scene):
            request["scene"] = value.scene
            if value.texture:
                if "texture" in options:
                    raise InputError("texture: is the Scene's own; give it to Scene.from_files", "texture")
                request["texture"] = value.texture
            continue
        spec = specs.get(key)
        value = _options.request_value(spec, value) if spec else value
        try:
            json.dumps(value, allow_nan=False)
        except (TypeError, ValueError):
            raise InputError(f"{key}: {value!r} is not a value this option takes", key) from None
        request[key] = value
    return json.dumps(request, allow_nan=False)


def render(*, device: Optional[str] = None, progress: Optional[Callable[[str], None]] = None,
           **options) -> RenderResult:
    """Renders one frame: the render job of `seamcl render --json`. Raises InputError (a
    ValueError) naming the option at fault; KeyboardInterrupt (Ctrl-C) stops it between renders."""
    info, image, address = _seamcl.render(_request("render", options), _device(device), progress)
    return RenderResult(image=image, info=json.loads(info), _buffer_address=address)


def compare(*, device: Optional[str] = None, images: bool = False, cache: Optional[str] = None,
            no_cache: bool = False, progress: Optional[Callable[[str], None]] = None, **options) -> CompareResult:
    """Renders one frame with every method x MSAA rate and measures each against the references:
    the compare job of `seamcl compare --json`. With images=True, the images, error maps,
    references and seam masks as arrays too. cache: the reference cache's directory (default
    $SEAMCL_CACHE_DIR, else ~/.cache/seamcl); no_cache: always render the references."""
    if cache is not None and (not isinstance(cache, str) or not cache):
        raise InputError("cache: must not be empty (leave it out for $SEAMCL_CACHE_DIR or ~/.cache/seamcl)", "cache")
    info, arrays, references, first, masks = _seamcl.compare(
        _request("compare", options), _device(device), cache or "", not no_cache, progress, bool(images))
    info = json.loads(info)
    keys = [(r["method"], r["msaa"]) for r in info["results"]]
    return CompareResult(
        info=info, results=info["results"],
        images={key: image for key, (image, _) in zip(keys, arrays)},
        error_maps={key: distance for key, (_, distance) in zip(keys, arrays) if distance is not None},
        reference=references.get(first) if images else None,
        references=dict(references), seam_masks=dict(masks))


def devices(device: Optional[str] = None) -> List[dict]:
    """The OpenCL devices (`seamcl devices`): platform, name, type, version, compute_units,
    global_memory_bytes, host_unified_memory, and chosen for the one `device` selects."""
    return json.loads(_seamcl.devices(_device(device)))


def scenes() -> List[dict]:
    """The built-in scenes (`seamcl scenes --json`): name and description."""
    return json.loads(_seamcl.scenes())


def _describe(function, job: str, own: list, summary: str):
    function.__signature__ = _options.signature(job, own)
    function.__doc__ = f"{summary}\n\nOptions (the {job} job's option table):\n{_options.doc_lines(job)}"


_K = inspect.Parameter.KEYWORD_ONLY
_describe(render, "render", [inspect.Parameter("device", _K, default=None),
                             inspect.Parameter("progress", _K, default=None)], render.__doc__)
_describe(compare, "compare", [inspect.Parameter("device", _K, default=None),
                               inspect.Parameter("images", _K, default=False),
                               inspect.Parameter("cache", _K, default=None),
                               inspect.Parameter("no_cache", _K, default=False),
                               inspect.Parameter("progress", _K, default=None)], compare.__doc__)
