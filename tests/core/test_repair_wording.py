"""Counts in the sliver repair's report are grammatical ("1 vertex fewer")."""

import modalviewer as mv
from benchmarks.slivers import add_slivers
from modalviewer.core.primitives import icosphere


def test_one_needle_removed_reads_one_vertex_fewer():
    v, f = add_slivers(icosphere(2), needles=1, caps=0, eps=1e-8, seed=2)
    report = mv.fix_slivers(mv.Mesh(v, f)).report
    assert report.vertices_removed == 1
    text = str(report)
    assert "1 vertex fewer" in text and "1 vertices" not in text
    assert f"of {report.triangles_before} triangles" in text
