"""The reference cache: hits do not re-render, any change of scene, options, size or referenced
file is a miss, damaged entries are recomputed, writes leave no partial files."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import workbench
from workbench.compare import reference_cache as rc
from workbench.renderers.base import RenderResult
from workbench.scene import model as m


@pytest.fixture
def counted(monkeypatch):
    """Replace the cache's render with a fake that counts calls (image from the options)."""
    calls = []

    def fake(scene, method, *, width, height, **options):
        calls.append((scene.name, method, width, height, dict(options)))
        rng = np.random.default_rng(len(calls))
        img = rng.random((height, width, 3)).astype(np.float32)
        return RenderResult(method, img, {"total": 1.5}, {"stderr": img * 0.01, "stderr_rms": 0.004,
                                                          "variant": "scalar_rgb"},
                            ["area_lights"], [], dict(options), depth=np.ones((height, width), np.float32))
    monkeypatch.setattr(rc, "render", fake)
    return calls


def test_second_call_is_a_hit_and_returns_the_same_result(tmp_path, counted):
    s = workbench.load_scene("cornell")
    a = rc.cached_render(s, "mitsuba", 12, 10, directory=tmp_path, spp=8)
    b = rc.cached_render(s, "mitsuba", 12, 10, directory=tmp_path, spp=8)
    assert len(counted) == 1
    assert a.stats["cache"] == "miss" and b.stats["cache"] == "hit"
    assert np.array_equal(a.image, b.image) and b.image.dtype == np.float32
    assert np.array_equal(a.stats["stderr"], b.stats["stderr"]) and b.stats["stderr_rms"] == 0.004
    assert np.array_equal(a.depth, b.depth)
    assert b.left_out == [] and b.features_used == ["area_lights"] and b.timings["total"] == 1.5
    # defaults filled in before keying: spp = 64 is the default, so {} and {spp: 64} share an entry
    rc.cached_render(s, "mitsuba", 12, 10, directory=tmp_path)
    rc.cached_render(s, "mitsuba", 12, 10, directory=tmp_path, spp=64)
    assert len(counted) == 2
    assert not list(tmp_path.glob(".tmp-*"))
    meta = rc.cache_entries(tmp_path)
    assert len(meta) == 2 and {e["options"]["spp"] for e in meta} == {8, 64}
    assert all(e["noise"]["stderr_rms"] == 0.004 for e in meta)


def test_changed_scene_options_or_size_is_a_miss(tmp_path, counted):
    s = workbench.load_scene("cornell")
    rc.cached_render(s, "mitsuba", 12, 10, directory=tmp_path, spp=8)
    red = dataclasses.replace(s.materials["red"], color=(0.5, 0.04, 0.01))
    s2 = dataclasses.replace(s, materials={**s.materials, "red": red})
    rc.cached_render(s2, "mitsuba", 12, 10, directory=tmp_path, spp=8)
    rc.cached_render(s, "mitsuba", 12, 10, directory=tmp_path, spp=16)
    rc.cached_render(s, "mitsuba", 12, 10, directory=tmp_path, spp=8, seed=1)
    rc.cached_render(s, "mitsuba", 10, 12, directory=tmp_path, spp=8)
    moved = dataclasses.replace(s, lights=(dataclasses.replace(s.lights[0], intensity=1.01),))
    rc.cached_render(moved, "mitsuba", 12, 10, directory=tmp_path, spp=8)
    assert len(counted) == 6
    rc.cached_render(s2, "mitsuba", 12, 10, directory=tmp_path, spp=8)
    assert len(counted) == 6


def test_the_scene_file_location_does_not_matter_but_a_referenced_file_does(tmp_path):
    png = tmp_path / "tex.png"
    from PIL import Image
    Image.fromarray(np.zeros((4, 4, 3), np.uint8)).save(png)
    cam = m.Camera(position=(0.0, 0.0, 5.0), look_at=(0.0, 0.0, 0.0))
    tex = m.Texture("image", projection="planar", path=str(png))
    s = m.Scene("t", cam, {"a": m.Material("a", texture=tex)}, (m.Sphere("a"),),
                lights=(m.PointLight((0.0, 2.0, 2.0)),), source="/somewhere/t.toml")
    k1 = rc.cache_key(s, "mitsuba", 8, 8)
    assert rc.cache_key(dataclasses.replace(s, source="/elsewhere/t.toml"), "mitsuba", 8, 8) == k1
    Image.fromarray(np.full((4, 4, 3), 9, np.uint8)).save(png)
    assert rc.cache_key(s, "mitsuba", 8, 8) != k1


@pytest.mark.parametrize("damage", ["garbage_image", "flipped_pixel", "truncated_json", "missing_arrays"])
def test_a_damaged_entry_is_ignored_and_recomputed(tmp_path, counted, damage):
    s = workbench.load_scene("cornell")
    rc.cached_render(s, "mitsuba", 12, 10, directory=tmp_path, spp=8)
    key = rc.cache_key(s, "mitsuba", 12, 10, spp=8)
    img_p, arr_p, meta_p = (tmp_path / f"{key}{ext}" for ext in (".npy", ".arrays.npz", ".json"))
    if damage == "garbage_image":
        img_p.write_bytes(b"not an array")
    elif damage == "flipped_pixel":  # still a valid .npy, but not the image that was stored
        a = np.load(img_p)
        a[3, 4, 1] += 0.25
        np.save(img_p, a)
    elif damage == "truncated_json":
        meta_p.write_text(meta_p.read_text()[:40])
    else:
        arr_p.unlink()
    assert rc.load_entry(key, tmp_path) is None
    r = rc.cached_render(s, "mitsuba", 12, 10, directory=tmp_path, spp=8)
    assert len(counted) == 2 and r.stats["cache"] == "miss"
    assert rc.load_entry(key, tmp_path) is not None  # rewritten intact


def test_location_from_the_environment_and_clearing(tmp_path, monkeypatch, counted):
    monkeypatch.setenv(rc.ENV_VAR, str(tmp_path / "refs"))
    assert rc.cache_dir() == tmp_path / "refs"
    monkeypatch.delenv(rc.ENV_VAR)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert rc.cache_dir() == tmp_path / "xdg" / "workbench" / "references"
    monkeypatch.setenv(rc.ENV_VAR, str(tmp_path / "refs"))
    s = workbench.load_scene("cornell")
    rc.cached_render(s, "mitsuba", 6, 6, spp=8)
    assert rc.clear_cache() == 3 and not list((tmp_path / "refs").iterdir())
    rc.cached_render(s, "mitsuba", 6, 6, spp=8)
    assert len(counted) == 2


def test_a_real_mitsuba_reference_round_trips(tmp_path):
    s = workbench.load_scene("cornell")
    a = rc.cached_render(s, "mitsuba", 16, 16, directory=tmp_path, spp=4)
    b = rc.cached_render(s, "mitsuba", 16, 16, directory=tmp_path, spp=4)
    assert (a.stats["cache"], b.stats["cache"]) == ("miss", "hit")
    assert np.array_equal(a.image, b.image) and np.array_equal(a.stats["stderr"], b.stats["stderr"])
    assert b.stats["variant"] == a.stats["variant"]
