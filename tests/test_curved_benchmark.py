"""benchmarks/curved.py: its cases and one small run of its child process."""

import argparse

import numpy as np
import pytest

import modalviewer as mv
from benchmarks import curved


def test_a_case_is_asset_scheme_level_and_a_bad_one_says_what_is_expected():
    assert curved.parse_case("hand:loop:2") == ("hand", "loop", 2)
    for bad in ("hand:loop", "horse:loop:1", "part:cubic:1", "part:flat:-1", "spot:loop:x"):
        with pytest.raises(argparse.ArgumentTypeError, match="asset:scheme:level"):
            curved.parse_case(bad)


def test_a_flat_subdivision_of_the_part_keeps_its_shape_and_runs():
    """One split in four: a vertex per edge more; the child returns the five non-zero
    eigenvalues of six exact Laplacian modes (one zero mode: one component), sorted."""
    part = mv.load_mesh(mv.asset_path("demo_machined_part.obj"))
    row = curved.run(("part", "flat", 1), "laplacian", 6)
    assert row["vertices"] == part.n_vertices + part.edges.shape[0]
    assert len(row["eigenvalues"]) == 5 and np.all(np.diff(row["eigenvalues"]) >= 0)
    assert row["seconds"] > 0
