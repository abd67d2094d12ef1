"""The preset registry (fcplan.env.presets): names, classes, the maker, the old import paths and
the base module that knows no preset."""

from __future__ import annotations

import ast
import inspect

import pytest
from pettingzoo import ParallelEnv

import fcplan.env.motion_base as motion_base
import fcplan.env.motion_cmplx as motion_cmplx
import fcplan.env.motion_presets as motion_presets
import fcplan.env.presets.core as core
from fcplan.env import EnvError, presets
from fcplan.env.motion import parallel_env
from fcplan.env.presets import PRESETS, CmplxEnv, PresetEnv, make_preset


def test_every_name_maps_to_a_preset_class():
    """PRESETS maps base, cmplx1 and cmplx2 to PresetEnv subclasses; make_preset builds that
    class with the keyword arguments, and cmplx1/cmplx2 are CmplxEnv of that variant."""
    assert list(PRESETS) == ["base", "cmplx1", "cmplx2"]
    for name, cls in PRESETS.items():
        env = make_preset(name, max_steps=7)
        assert type(env) is cls and isinstance(env, PresetEnv) and env.max_steps == 7
    for variant in ("cmplx1", "cmplx2"):
        env = make_preset(variant)
        assert isinstance(env, CmplxEnv) and env.variant == variant
        assert type(parallel_env(preset=variant)) is PRESETS[variant]


def test_cmplx_variant_classes_roll_out_like_cmplx_env():
    """A Cmplx1Env/Cmplx2Env plays exactly as CmplxEnv(variant=...) with the same seed."""
    for variant in ("cmplx1", "cmplx2"):
        a, b = make_preset(variant, max_steps=20), CmplxEnv(variant=variant, max_steps=20)
        oa, _ = a.reset(seed=4)
        ob, _ = b.reset(seed=4)
        for step in range(20):
            acts = {ag: (step + k) % int(a.action_space(ag).n) for k, ag in enumerate(a.agents)}
            ra, rb = a.step(acts), b.step(acts)
            assert ra[1] == rb[1] and (a.state() == b.state()).all()
            assert all((ra[0][ag]["fov"] == rb[0][ag]["fov"]).all() for ag in ra[0])


def test_unknown_preset_is_an_env_error():
    """An unknown name raises EnvError listing the presets."""
    with pytest.raises(EnvError, match=r"preset: must be one of base, cmplx1, cmplx2 \(got 'x'\)"):
        make_preset("x")


def test_old_import_paths_export_the_same_objects():
    """fcplan.env.motion_presets, motion_base and motion_cmplx re-export the presets' objects."""
    for module in (motion_presets, motion_base, motion_cmplx):
        for name in module.__all__:
            assert getattr(module, name) is getattr(presets, name), (module.__name__, name)


def test_the_base_module_imports_no_preset():
    """fcplan.env.presets.core imports nothing from the preset modules or the package (the
    registry is filled by the package, not by the base class), and it takes PettingZoo's
    ParallelEnv directly."""
    tree = ast.parse(inspect.getsource(core))
    imported = {
        node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module
    } | {a.name for node in ast.walk(tree) if isinstance(node, ast.Import) for a in node.names}
    assert not {m for m in imported if m.startswith("fcplan.env")}
    assert "pettingzoo" in imported and issubclass(core.PresetEnv, ParallelEnv)
