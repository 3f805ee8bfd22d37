"""Arguments at the public API's edge: k, vertex indices, scales, load_spectrum's mesh,
Spectrum's repr, the py.typed marker (issue 28)."""

import re
from pathlib import Path

import numpy as np
import pytest

import modalviewer as mv
from modalviewer.core.primitives import icosphere
from modalviewer.core.signatures import SignatureTable


@pytest.fixture(scope="module")
def sphere():
    return icosphere(2)  # 162 vertices


@pytest.fixture(scope="module")
def lap(sphere):
    return mv.compute_spectrum(sphere, "laplacian", k=8)


@pytest.fixture(scope="module")
def shells(sphere):
    return mv.compute_spectrum(sphere, "shells", k=12)


# --- k -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("k", "error", "message"),
    [
        (2.5, TypeError, "k must be an integer, got 2.5"),  # was silently 2 modes
        (2.0, TypeError, "k must be an integer, got 2.0"),
        ("3", TypeError, "k must be an integer, got '3'"),
        (True, TypeError, "k must be an integer, got True"),
        (np.float64(3.0), TypeError, "k must be an integer, got 3.0"),
        (0, ValueError, "k must be at least 1, got 0"),
        (-4, ValueError, "k must be at least 1, got -4"),
    ],
)
def test_bad_k_is_refused_naming_k_and_the_value(sphere, k, error, message):
    with pytest.raises(error, match=f"^{re.escape(message)}$"):
        mv.compute_spectrum(sphere, "laplacian", k=k)
    with pytest.raises(error, match=f"^{re.escape(message)}$"):
        mv.compute_spectrum_per_component(sphere, "laplacian", k=k)


def test_k_as_a_numpy_integer_works(sphere, lap):
    for k in (np.int64(8), np.int32(8), np.array(8)):
        spec = mv.compute_spectrum(sphere, "laplacian", k=k)
        assert spec.k == 8 and type(spec.parameters["k"]) is int
        np.testing.assert_allclose(spec.eigenvalues, lap.eigenvalues, rtol=1e-8, atol=1e-10)
    (part,) = mv.compute_spectrum_per_component(sphere, "laplacian", k=np.int64(5))
    assert part.spectrum.k == 5


# --- vertex indices --------------------------------------------------------------------


def _vertex_calls(lap):
    table = SignatureTable(lap)
    tables = mv.CrossTables(lap, lap)
    return {
        "multiscale_distance": lambda v: mv.multiscale_distance(lap, v),
        "cross_distance": lambda v: mv.cross_distance(lap, v, lap),
        "best_match": lambda v: mv.best_match(lap, v, lap),
        "SignatureTable.distance_from": table.distance_from,
        "CrossTables.a_to_b": tables.a_to_b,
        "CrossTables.b_to_a": tables.b_to_a,
    }


def test_a_float_vertex_is_refused(lap):
    for name, call in _vertex_calls(lap).items():
        with pytest.raises(TypeError, match=r"^vertex must be an integer index, got 2\.0$"):
            call(2.0)
        with pytest.raises(TypeError, match=r"^vertex must be an integer index, got 2\.0$"):
            call(np.float64(2.0))
        with pytest.raises(TypeError, match="got True"):
            call(True)
        assert call(np.int32(2)) is not None, name


@pytest.mark.parametrize("vertex", [162, 10**6, -1])
def test_a_vertex_out_of_range_names_the_number_of_vertices(lap, vertex):
    for call in _vertex_calls(lap).values():
        with pytest.raises(
            IndexError,
            match=rf"^vertex {vertex} out of range: the mesh has 162 vertices \(0\.\.161\)$",
        ):
            call(vertex)


def test_integer_vertices_of_every_integer_type_give_the_same_result(lap):
    d = mv.multiscale_distance(lap, 5)
    for v in (np.int32(5), np.int64(5), np.uint16(5), np.array(5)):
        np.testing.assert_array_equal(mv.multiscale_distance(lap, v), d)
        np.testing.assert_array_equal(SignatureTable(lap).distance_from(v), d)
    assert mv.best_match(lap, np.int32(5), lap)[0] == 5


def test_vertex_lists(lap):
    with pytest.raises(TypeError, match=r"^vertices_a must be integer vertex indices"):
        mv.mutual_best_matches(lap, [1.0, 2.0], lap)
    with pytest.raises(IndexError, match=r"vertices_b: vertex 500 out of range: .*162 vertices"):
        mv.mutual_best_matches(lap, [1], lap, [3, 500])
    with pytest.raises(ValueError, match="non-empty"):
        mv.mutual_best_matches(lap, [], lap)
    d = mv.multiscale_distance(lap, 0)
    with pytest.raises(TypeError, match="integer vertex indices"):
        mv.distance_ranks(d, [0.0])
    np.testing.assert_array_equal(mv.distance_ranks(d, np.array([0], np.int32)), [1])
    with pytest.raises(TypeError, match="vertices must be integer vertex indices"):
        mv.signature(lap, vertices=[2.0])
    with pytest.raises(IndexError, match="vertices: vertex 162 out of range"):
        mv.signature(lap, vertices=[0, 162])
    with pytest.raises(IndexError, match="vertices: vertex -1 out of range"):
        mv.signature(lap, vertices=[-1])
    _, whole = mv.signature(lap)
    _, some = mv.signature(lap, vertices=np.array([3, 7], np.int32))
    np.testing.assert_array_equal(some, whole[[3, 7]])


# --- scales ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("times", "message"),
    [
        ([-1], "times must be positive and finite, got -1.0"),  # gave values near 4e4
        ([0.1, 0.0], "times must be positive and finite, got 0.0"),
        ([np.nan], "times must be positive and finite, got nan"),
        ([1.0, np.inf], "times must be positive and finite, got inf"),
        (-0.5, "times must be positive and finite, got -0.5"),
        ([], "times must be one scale or a non-empty 1-D sequence of them"),
        ([[0.1, 0.2]], "times must be one scale or a non-empty 1-D sequence of them"),
    ],
)
def test_bad_times_are_refused(lap, times, message):
    with pytest.raises(ValueError, match=f"^{re.escape(message)}$"):
        mv.signature(lap, times=times)


def test_times_that_are_not_numbers(lap):
    with pytest.raises(TypeError, match="times must be numbers, got 'abc'"):
        mv.signature(lap, times="abc")


def test_good_times_still_work(lap):
    t, values = mv.signature(lap, times=0.1)
    assert t.shape == (1,) and values.shape == (162, 1) and np.all(values > 0)
    t, values = mv.signature(lap, times=np.array([0.01, 0.1], np.float32))
    assert values.shape == (162, 2)


@pytest.mark.parametrize(
    ("t_range", "error", "message"),
    [
        ((-1.0, 1.0), ValueError, "t_range must be positive and finite, got -1.0"),
        ((0.0, 1.0), ValueError, "t_range must be positive and finite, got 0.0"),
        ((0.1, np.nan), ValueError, "t_range must be positive and finite, got nan"),
        ((2.0, 1.0), ValueError, "the scale range needs 0 < t1 < t2, got t_range=(2, 1)"),
        ((1.0, 2.0, 3.0), TypeError, "t_range must be a pair (t1, t2), got (1.0, 2.0, 3.0)"),
        (0.5, TypeError, "t_range must be a pair (t1, t2), got 0.5"),
    ],
)
def test_bad_scale_ranges_are_refused(lap, t_range, error, message):
    pattern = f"^{re.escape(message)}$"
    with pytest.raises(error, match=pattern):
        mv.multiscale_distance(lap, 0, t_range=t_range)
    with pytest.raises(error, match=pattern):
        mv.cross_distance(lap, 0, lap, t_range=t_range)
    with pytest.raises(error, match=pattern):
        mv.common_times(lap, lap, t_range=t_range)
    with pytest.raises(error, match=pattern):
        SignatureTable(lap, t_range=t_range)


@pytest.mark.parametrize(
    ("samples", "error", "message"),
    [
        (1, ValueError, "samples must be at least 2, got 1"),
        (10.5, TypeError, "samples must be an integer, got 10.5"),
    ],
)
def test_bad_samples_are_refused(lap, samples, error, message):
    pattern = f"^{re.escape(message)}$"
    with pytest.raises(error, match=pattern):
        mv.multiscale_distance(lap, 0, samples=samples)
    with pytest.raises(error, match=pattern):
        mv.common_times(lap, lap, samples=samples)
    with pytest.raises(error, match=pattern):
        mv.default_times(lap, samples)


def test_numpy_samples_work(lap):
    assert mv.common_times(lap, lap, samples=np.int64(7)).shape == (7,)
    assert mv.multiscale_distance(lap, 0, samples=np.int32(7)).shape == (162,)


# --- load_spectrum ---------------------------------------------------------------------


def test_load_spectrum_takes_the_mesh(tmp_path, sphere, lap):
    path = tmp_path / "s.npz"
    mv.save_spectrum(lap, path)
    back = mv.load_spectrum(path, sphere)  # raised "belongs to another mesh" before
    np.testing.assert_array_equal(back.eigenvalues, lap.eigenvalues)
    assert mv.load_spectrum(path, mesh=sphere).k == lap.k
    assert mv.load_spectrum(path, mesh_hash=sphere.hash).k == lap.k
    with pytest.raises(mv.SpectrumFileError, match="belongs to another mesh"):
        mv.load_spectrum(path, icosphere(1))
    with pytest.raises(mv.SpectrumFileError, match="belongs to another mesh"):
        mv.load_spectrum(path, mesh_hash="0" * 64)


def test_load_spectrum_refuses_a_hash_as_the_mesh(tmp_path, sphere, lap):
    path = tmp_path / "s.npz"
    mv.save_spectrum(lap, path)
    with pytest.raises(TypeError, match=r"mesh must be a Mesh; .*pass mesh_hash="):
        mv.load_spectrum(path, sphere.hash)
    with pytest.raises(TypeError, match="mesh must be a Mesh, got int"):
        mv.load_spectrum(path, 3)
    with pytest.raises(TypeError, match="not both"):
        mv.load_spectrum(path, sphere, mesh_hash=sphere.hash)
    with pytest.raises(TypeError, match="mesh_hash must be a string"):
        mv.load_spectrum(path, mesh_hash=sphere)


# --- repr and py.typed -----------------------------------------------------------------


def test_spectrum_repr_is_one_short_line(lap, shells):
    assert repr(shells) == (
        "Spectrum(operator='shells', k=12, n_vertices=162, modes=(162, 3, 12), "
        f"eigenvalues={shells.eigenvalues.min():.3g} .. {shells.eigenvalues.max():.3g})"
    )
    text = repr(lap)
    assert text.startswith("Spectrum(operator='laplacian', k=8, n_vertices=162, modes=(162, 8)")
    assert text.endswith(")") and "\n" not in text and "array" not in text
    assert len(text) < 150


@pytest.mark.parametrize("accuracy", ["preview", "fast preview"])
def test_the_removed_preview_accuracies_say_what_to_use_instead(sphere, accuracy):
    """The approximate previews are gone: asking for one is a ValueError that names the
    callback for early modes and fewer modes, before any work."""
    with pytest.raises(ValueError, match="preview spectrum was removed") as caught:
        mv.compute_spectrum(sphere, "laplacian", k=8, accuracy=accuracy)
    assert "on_modes=" in str(caught.value) and "fewer modes k" in str(caught.value)
    with pytest.raises(ValueError, match="accuracy must be 'exact', got 'rough'"):
        mv.compute_spectrum(sphere, "laplacian", k=8, accuracy="rough")
    assert mv.compute_spectrum(sphere, "laplacian", k=8, accuracy="exact").k == 8


def test_py_typed_marker_is_shipped():
    import tomllib

    root = Path(mv.__file__).resolve().parent
    assert (root / "py.typed").is_file()
    with open(root.parent / "pyproject.toml", "rb") as fh:
        config = tomllib.load(fh)
    assert "py.typed" in config["tool"]["setuptools"]["package-data"]["modalviewer"]


def test_a_spectrum_file_saved_with_a_previews_fields_loads(sphere, lap, tmp_path):
    """Files written while previews existed carry ``parameters["preview"]`` (estimates,
    samples): they load as any spectrum, the field kept as data and used by nothing."""
    old = mv.Spectrum(
        lap.eigenvalues, lap.modes, lap.operator, lap.mass, lap.residuals, lap.mesh_hash,
        {**lap.parameters, "preview": {"estimated_error": 0.02, "samples": 600}},
    )  # fmt: skip
    path = tmp_path / "old.npz"
    mv.save_spectrum(old, path)
    back = mv.load_spectrum(path, sphere)
    np.testing.assert_array_equal(back.eigenvalues, lap.eigenvalues)
    assert back.parameters["preview"]["samples"] == 600
    assert not hasattr(back, "is_preview") and "preview" not in repr(back)
