"""seamcl.compare against `seamcl compare --json` of the same build, and its arrays against the
figures and against seamcl.render of each entry."""
import numpy as np
import pytest

import seamcl

# A compare's figures that depend on the run (times, memory, where the reference came from).
TIMED = {"ms", "memory", "reference", "references", "timing"}


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("reference-cache")


@pytest.fixture(scope="module")
def compared(cli_json, cache):
    """The CLI's answer (it renders the reference into `cache`) and the package's (reading it)."""
    expected = cli_json("compare", "--scene", "quad2", "--size", "48x40", "--methods", "discard,traverse",
                        "--msaa", "1,4", "--repeat", "1", "--cache", cache, "--json", "--no-progress")
    lines = []
    c = seamcl.compare(scene="quad2", size=(48, 40), methods=["discard", "traverse"], msaa=[1, 4], repeat=1,
                       cache=str(cache), images=True, progress=lines.append)
    return expected, c, lines


def test_results_equal_the_clis(compared):
    expected, c, _ = compared
    assert c.results is c.info["results"]
    assert [(r["method"], r["msaa"]) for r in c.results] == [("discard", 1), ("discard", 4), ("traverse", 1),
                                                              ("traverse", 4)]
    assert set(c.info) == set(expected)
    for key in set(expected) - TIMED - {"results"}:
        assert c.info[key] == expected[key], key
    for mine, theirs in zip(c.results, expected["results"]):
        assert {k: v for k, v in mine.items() if k != "ms"} == {k: v for k, v in theirs.items() if k != "ms"}
    # The same reference: the CLI's, read from the cache; the rest of its description equal.
    assert c.info["reference"]["from_cache"] and not expected["reference"]["from_cache"]
    strip = lambda ref: {k: v for k, v in ref.items() if k not in ("from_cache", "ms", "kernel_ms")}
    assert strip(c.info["reference"]) == strip(expected["reference"])


def test_arrays_hold_what_the_figures_measure(compared):
    _, c, _ = compared
    height, width = 40, 48
    assert c.reference.shape == (height, width, 4) and c.reference.dtype == np.float32
    assert c.info["reference"]["name"] == "paper" and set(c.references) == {"paper"}
    assert c.references["paper"] is c.reference
    for result in c.results:
        key = (result["method"], result["msaa"])
        image, distance = c.images[key], c.error_maps[key]
        assert image.shape == (height, width, 4) and distance.shape == (height, width)
        # The error map is the per-pixel distance the figures are statistics of.
        assert np.nanmean(distance) == pytest.approx(result["error"]["mean"], rel=1e-5, abs=1e-9)
        assert np.nanmax(distance) == pytest.approx(result["error"]["max"], rel=1e-5, abs=1e-9)
    for msaa, mask in c.seam_masks.items():
        assert mask.dtype == np.uint8 and mask.shape == (height, width)
        assert int((mask == 1).sum()) == c.info["seam_mask"]["by_msaa"][str(msaa)]["pixels"]
    assert set(c.seam_masks) == {1, 4}


def test_each_image_is_the_render_of_its_entry(compared):
    _, c, _ = compared
    for (method, msaa), image in c.images.items():
        r = seamcl.render(scene="quad2", size=(48, 40), method=method, msaa=msaa)
        np.testing.assert_array_equal(image, r.image)


def test_progress_reports_each_entry(compared):
    _, _, lines = compared
    entries = [line for line in lines if line.startswith("entry ")]
    assert len(entries) == 4 and entries[0].startswith("entry 1/4") and "traverse" in entries[-1]


def test_without_images_only_the_figures():
    c = seamcl.compare(scene="quad2", size=(16, 16), methods=["clamp"], msaa=[1], repeat=1, no_cache=True)
    assert c.images == {} and c.error_maps == {} and c.reference is None and c.seam_masks == {}
    assert c.results[0]["method"] == "clamp" and c.results[0]["error"]["pixels"] == 256


@pytest.mark.parametrize("keywords,field", [(dict(methods=["bogus"]), "methods"), (dict(msaa=[3]), "msaa"),
                                            (dict(reference="nope"), "reference"), (dict(repeat=0), "repeat"),
                                            (dict(cache="/dev/null"), "cache")])
def test_bad_compare_options_name_the_field_as_the_cli(keywords, field, cli):
    flags = {"methods": ["--methods", "bogus"], "msaa": ["--msaa", "3"], "reference": ["--reference", "nope"],
             "repeat": ["--repeat", "0"], "cache": ["--cache", "/dev/null"]}[field]
    done = cli("compare", "--scene", "quad2", "--size", "16x16", *flags, check=False)
    assert done.returncode == 2
    with pytest.raises(seamcl.InputError) as caught:
        seamcl.compare(scene="quad2", size=(16, 16), **keywords)
    assert caught.value.field == field
    assert done.stderr.strip() == f"seamcl: {caught.value}"
