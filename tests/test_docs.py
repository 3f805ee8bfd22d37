"""The documentation: the API page lists every exported name, the performance tables come
from the benchmark results, and the Sphinx build passes with warnings as errors."""

import importlib.util
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
sys.path.insert(0, str(DOCS / "_ext"))

import api_page  # noqa: E402
import benchmark_tables  # noqa: E402


def test_api_page_documents_every_exported_name():
    import modalviewer

    source = api_page.api_source()
    documented = set(re.findall(r"^\.\. auto\w+:: (\w+)$", source, re.M))
    missing = [name for name in modalviewer.__all__ if name not in documented]
    assert not missing, missing
    assert ".. include:: _generated/api.inc" in (DOCS / "api.rst").read_text()


def test_api_page_is_written_only_when_it_changes(tmp_path):
    path = tmp_path / "api.inc"
    assert api_page.write_api_page(path)
    assert not api_page.write_api_page(path)
    assert path.read_text() == api_page.api_source()


def test_spectra_table_reproduces_latest_json():
    rows = json.loads((ROOT / "benchmarks/results/latest.json").read_text())
    table = benchmark_tables.render("spectra")
    lines = table.splitlines()
    assert len(lines) == 2 + len(rows)
    first = rows[0]
    cells = [c.strip() for c in lines[2].strip("|").split("|")]
    assert cells[:4] == [first["mesh"], str(first["vertices"]), first["operator"], str(first["k"])]
    assert cells[5] == f"{first['eigen_s']:.1f}"
    assert cells[11] == f"{first['peak_mb']:.0f}"


def test_every_table_comes_from_its_json():
    shells = json.loads((ROOT / "benchmarks/results/interactive_130k_shells.json").read_text())
    assert f"{shells['compute_s']:.1f} s" in benchmark_tables.render("viewer")
    slivers = json.loads((ROOT / "benchmarks/results/slivers.json").read_text())
    repair = slivers["fix_slivers"][0]
    assert f"{repair['triangles_changed']} of {repair['triangles_before']}" in (
        benchmark_tables.render("slivers")
    )
    rows = json.loads((ROOT / "benchmarks/results/latest.json").read_text())
    shells_300 = [r for r in rows if r["operator"] == "shells" and r["k"] == 300]
    paper = benchmark_tables.render("paper")
    assert all(f"{r['eigen_s']:.1f} s" in paper for r in shells_300)


def test_performance_page_marks_tables_and_its_copy_is_current():
    """Every marked table names a known table, and the copy in performance.md (the one
    GitHub shows) is the table made from the JSON results now; after a benchmark run,
    `.venv/bin/python docs/_ext/benchmark_tables.py` refreshes it."""
    text = (DOCS / "performance.md").read_text()
    names = re.findall(r"<!-- table: ([\w-]+) -->", text)
    readme = (ROOT / "README.md").read_text()
    in_readme = re.findall(r"<!-- table: ([\w-]+) -->", readme)
    assert sorted(in_readme) == sorted(benchmark_tables.README_TABLES)
    assert sorted(names + in_readme) == sorted(benchmark_tables.TABLES)
    assert benchmark_tables.fill(text) == text
    assert benchmark_tables.fill(readme) == readme  # the README's figures too


def test_performance_plots_are_drawn_from_the_json_and_marked_on_the_page(tmp_path):
    text = (DOCS / "performance.md").read_text()
    names = benchmark_tables.PLOT_MARK.findall(text)
    assert sorted(names) == sorted(benchmark_tables.PLOTS_MADE)
    paths = benchmark_tables.draw_plots(tmp_path)
    assert sorted(p.name for p in paths) == sorted(f"{n}.png" for n in names)
    assert all(p.stat().st_size > 10_000 for p in paths)
    page = benchmark_tables.with_plots(text)
    assert "<!-- plot: " not in page
    assert ":::{figure} _generated/plots/spectra.png" in page


@pytest.mark.slow
def test_sphinx_build_has_no_warnings(tmp_path):
    if (
        importlib.util.find_spec("sphinx") is None
        or importlib.util.find_spec("myst_parser") is None
    ):
        pytest.skip("sphinx and myst-parser are not installed (pip install -e '.[docs]')")
    out = tmp_path / "html"
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "sphinx",
            "-W",
            "--keep-going",
            "-E",
            "-q",
            "-b",
            "html",
            "-d",
            str(tmp_path / "doctrees"),
            str(DOCS),
            str(out),
        ],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert result.returncode == 0, result.stderr
    api = (out / "api.html").read_text()
    import modalviewer

    for name in modalviewer.__all__:
        assert f'id="modalviewer.{name}"' in api, name
    shutil.rmtree(out)


def test_docstring_entries_become_napoleon_fields():
    import docstrings

    lines = [
        "Parameters",
        "----------",
        "k : number of modes; capped at the number of unknowns.",
        "vertices : array_like, shape (n, 3)",
        "    Vertex positions.",
        "",
        "Returns",
        "-------",
        "The spectrum, |K u - lambda M u| small.",
    ]
    out = docstrings.normalise_sections(lines)
    assert out[2:4] == ["k", "    number of modes; capped at the number of unknowns."]
    assert out[4:6] == lines[3:5]  # numpy style (a type, its text below) stays
    assert (
        docstrings.escape_bars(out)[-1] == ":returns: The spectrum, \\|K u - lambda M u\\| small."
    )


def test_the_viewer_guide_lists_the_controls_help_shows():
    """docs/viewer-guide.md's Controls block is Help > Controls' text, line for line."""
    from modalviewer.gui.menus import CONTROLS

    guide = (DOCS / "viewer-guide.md").read_text()
    block = guide.split("## Controls", 1)[1].split("```", 2)[1]
    assert block.strip("\n") == CONTROLS
