"""An EXR as the CLI wrote it, read with OpenEXR's own Python bindings (PyPI's OpenEXR), not
through seamcl: (pixels as stored, float16 or float32, shape (H, W, 4)), the stored type's name."""
import numpy as np
import OpenEXR


def read_rgba(path):
    with OpenEXR.File(str(path), separate_channels=True) as f:
        channels = f.channels()
        planes = [channels[name].pixels for name in ("R", "G", "B", "A")]
    stored = {plane.dtype for plane in planes}
    assert len(stored) == 1, f"{path}: channels of several types {stored}"
    return np.stack(planes, axis=-1), stored.pop()
