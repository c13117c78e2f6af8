"""Shared fixtures for heron's colour checks (tests/python): the repository and scene
folders, the heron binary's path, and a session-wide cached `render` runner (see
heronrun.py). A missing heron binary makes each render test FAIL, never skip.
"""
from __future__ import annotations

import pathlib

import pytest

import herondist
from heronrun import REPO, SCENES, Renderer, heron_bin_path


@pytest.fixture(scope="session")
def repo_root() -> pathlib.Path:
    return REPO


@pytest.fixture(scope="session")
def scenes_dir() -> pathlib.Path:
    return SCENES


@pytest.fixture(scope="session")
def heron_bin() -> pathlib.Path:
    """Path of the heron binary (HERON_BIN or <repo>/target/release/heron); it may not
    exist: call require_heron_bin() inside a test to fail it with a clear message."""
    return heron_bin_path()


@pytest.fixture(scope="session")
def render(tmp_path_factory) -> Renderer:
    """render(scene_file_name, spp=, seed=, threads=, extra=(flags...)) -> Render (cached
    per session)."""
    return Renderer(tmp_path_factory)


@pytest.fixture(scope="session")
def dist_tarball(tmp_path_factory) -> pathlib.Path:
    """scripts/build-dist.sh's relocatable CLI tarball, built once per session."""
    return herondist.build_tarball(tmp_path_factory.mktemp("dist"))


@pytest.fixture(scope="session")
def dist_unpacked(dist_tarball, tmp_path_factory) -> pathlib.Path:
    """The tarball unpacked, then moved elsewhere under another name (its top folder)."""
    return herondist.unpack(dist_tarball, tmp_path_factory.mktemp("unpacked"),
                            tmp_path_factory.mktemp("moved") / "somewhere-else")
