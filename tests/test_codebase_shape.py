"""The package's shape, as ``scripts/codebase_metrics.py`` measures it: no import circle
(imports inside functions count too), no function over 120 lines, no module over 800
lines, at most 10 docstring lines citing a measurement from a particular run.

The line count of ``modalviewer/`` is printed by the script but not asserted here."""

import pytest


@pytest.fixture(scope="module")
def figures(codebase_metrics):
    return codebase_metrics.measure()


def test_no_import_circle_even_through_imports_inside_functions(figures):
    assert figures["import circles"] == []


def test_no_function_over_120_lines(figures):
    assert figures["functions over 120 lines"] == []


def test_no_module_over_800_lines(figures):
    assert figures["modules over 800 lines"] == []


def test_docstrings_state_rules_not_runs(figures, codebase_metrics):
    found = figures["docstring lines citing a measurement"]
    assert len(found) <= codebase_metrics.LIMITS["docstring lines citing a measurement"], found


def test_the_measures_see_what_they_look_for(codebase_metrics):
    metrics = codebase_metrics
    """Each measure finds its fault in a made-up graph or text (so the tests above can fail)."""
    assert metrics.import_circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [
        ["a", "b", "c"]
    ]
    assert metrics.import_circles({"a": {"b"}, "b": set()}) == []
    for line in ("took 63.2 s on the bunny", "uses 1.7 GB", "41 % of the surface"):
        assert metrics.MEASUREMENT.search(line), line
    for line in ("the first 10 modes", "eq. (31) with s = 2", "mode 5 of spectra"):
        assert not metrics.MEASUREMENT.search(line), line
