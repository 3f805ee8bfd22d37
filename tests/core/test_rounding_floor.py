"""Residuals above what well-shaped meshes reach are reported with their rounding floor:
the residual that rounding the mode to double precision alone causes."""

from pathlib import Path

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.assembly import operator_matrices
from modalviewer.core.pipeline import FLOOR_FACTOR, WELL_SHAPED_RESIDUAL
from modalviewer.core.primitives import icosphere
from modalviewer.viewer.wording import residual_text

ASSETS = Path(__file__).resolve().parents[2] / "assets"


def _floor(K, mass, lam, x):
    """eps | |K| |x| | / (|lam| |M x|), written out here independently of the solver."""
    K_abs = abs(K.tocsr())
    return (
        np.finfo(float).eps
        * np.linalg.norm(K_abs @ np.abs(x))
        / (abs(lam) * np.linalg.norm(mass * x))
    )


def test_a_residual_above_1e8_on_a_hand_is_at_its_rounding_floor():
    # the hand's thin fingers: 3D shells residual 6.8e-6, its floor 6.8e-6
    mesh = mv.load_mesh(ASSETS / "demo_hand.obj")
    spec = mv.compute_spectrum(mesh, "shells", k=30)
    nonzero = ~spec.zero_mode_mask()
    worst = int(np.flatnonzero(nonzero)[np.argmax(spec.residuals[nonzero])])
    assert spec.residuals[worst] > WELL_SHAPED_RESIDUAL
    K, mass = operator_matrices(mesh, "shells")
    x = spec.modes[..., worst].reshape(-1)
    expected = _floor(K, mass, spec.eigenvalues[worst], x)
    floor = spec.parameters["worst_residual_rounding_floor"]
    assert floor == pytest.approx(expected, rel=1e-6)
    assert spec.residuals[worst] <= FLOOR_FACTOR * floor
    text = residual_text(spec)
    assert f"{spec.residuals[worst]:.1e}" in text and "rounding floor" in text
    said = f"at the rounding floor of double precision for that mode here, about {floor:.1e}"
    assert said in text
    # three times the floor is not "at" it (it was said so up to ten times)
    spec.parameters["worst_residual_rounding_floor"] = spec.residuals[worst] / 3.0
    text = residual_text(spec)
    assert "(3 times the rounding floor of double precision for that mode here" in text
    assert "at the rounding floor" not in text


def test_a_well_shaped_mesh_reports_no_floor():
    spec = mv.compute_spectrum(icosphere(3), "shells", k=20)
    assert spec.residuals[~spec.zero_mode_mask()].max() < WELL_SHAPED_RESIDUAL
    assert spec.parameters["worst_residual_rounding_floor"] == 0.0
    assert "rounding floor" not in residual_text(spec)
