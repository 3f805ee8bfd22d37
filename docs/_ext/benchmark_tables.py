"""The performance tables, made from ``benchmarks/results/*.json``.

``docs/performance.md`` marks each generated table with a pair of comments::

    <!-- table: spectra -->
    | ... the table ... |
    <!-- end table -->

At build time (Sphinx's ``source-read`` event) every marked block is replaced by the table
made from the JSON results now in ``benchmarks/results``, so the HTML pages always show
the measured numbers.  The tables of ``make bench`` are made by the benchmark script's own
functions (``benchmarks.run.table``, ``benchmarks.run.stage_table``), the others here.

The plots of time and peak memory against mesh size are drawn with matplotlib from the
same files into ``docs/_generated/plots/`` when a build starts; the page marks each with
``<!-- plot: spectra -->`` (invisible on GitHub), which the HTML build replaces by the
image.

Run as a script, it rewrites the marked blocks of ``docs/performance.md`` in place (the
copy GitHub shows) and draws the plots::

    .venv/bin/python docs/_ext/benchmark_tables.py
"""

from __future__ import annotations

import importlib
import json
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "benchmarks" / "results"
PAGE = ROOT / "docs" / "performance.md"
README = ROOT / "README.md"
PLOTS = ROOT / "docs" / "_generated" / "plots"

MARKED = re.compile(r"(<!-- table: ([\w-]+) -->\n)(.*?)(<!-- end table -->)", re.S)
PLOT_MARK = re.compile(r"^<!-- plot: ([\w-]+) -->$", re.M)


def load(name: str):
    """One results file of benchmarks/results, by its name without ``.json``."""
    return json.loads((RESULTS / f"{name}.json").read_text())


def _benchmarks(name: str = "run"):
    """The module ``benchmarks.<name>`` (its ``table`` makes that benchmark's table)."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    return importlib.import_module(f"benchmarks.{name}")


def benchmark_table(name: str):
    """The table of ``benchmarks.<name>``, made by its own ``table`` from its results."""
    return lambda: _benchmarks(name).table(load(name))


def spectra_table(rows: list[dict]) -> str:
    """``make bench``'s spectra table (``benchmarks.run.table``)."""
    return _benchmarks().table(rows)


def stage_table(rows: list[dict]) -> str:
    """``make bench``'s table of the solver's stages (``benchmarks.run.stage_table``)."""
    return _benchmarks().stage_table(rows)


#: The paper's Table 1 (Chinese dragon, 2.66 GHz MacBook Pro, MUMPS, vibration modes, 300
#: modes), seconds: vertices -> (Hessian, eigenproblem, signature at all vertices).
PAPER_TABLE_1 = {"10k": (1, 58, 4), "50k": (4, 326, 30), "130k": (11, 1122, 100)}


def paper_table(rows: list[dict]) -> str:
    """The paper's Table 1 beside the 300-mode Discrete Shells rows of ``make bench``."""
    lines = [
        "| vertices | Hessian (paper / here) | eigenproblem (paper / here) "
        "| signature at all vertices (paper / here) |",
        "|" + " --- |" * 4,
    ]
    for mesh, (hessian, eigen, signature) in PAPER_TABLE_1.items():
        here = [r for r in rows if (r["mesh"], r["operator"], r["k"]) == (mesh, "shells", 300)]
        if not here:
            continue
        r = here[0]
        lines.append(
            f"| {mesh} | {hessian} s / {r['assembly_s']:.2f} s | {eigen} s / {r['eigen_s']:.1f} s "
            f"| {signature} s / {r['signature_s']:.2f} s |"
        )
    return "\n".join(lines)


#: The viewer benchmark's targets, per row of the table.
VIEWER_ROWS = [
    ("compute (child process)", lambda r: f"{r['compute_s']:.1f} s", "-"),
    (
        "longest event-loop gap while computing (10 ms timer, view idle)",
        lambda r: f"{r['longest_event_loop_gap_ms']:.0f} ms",
        "100 ms",
    ),
    ("Cancel to stopped", lambda r: f"{r['cancel_s']:.2f} s", "1 s"),
    (
        "reopen the cached spectrum (signature table ready after)",
        lambda r: f"{r['cached_reopen_s']:.2f} s ({r['table_ready_after_reopen_s']:.2f} s)",
        "1 s",
    ),
    ("mode switch with isolines, app (median / max)", lambda r: _ms(r["mode_switch"], 1), "60 ms"),
    ("animation frame, app (median / max)", lambda r: _ms(r["animation_frame"], 2), "10 ms"),
    (
        "pick to distance map, app (median / max)",
        lambda r: _ms(r["pick_to_distance_map"], 1),
        "30 ms",
    ),
    ("first pick", lambda r: f"{r['first_pick_with_table_ms']:.0f} ms", "30 ms"),
    ("threshold-slider step, app (median / max)", lambda r: _ms(r["threshold_step"], 2), "10 ms"),
    ("draw (software rendering, 1280 x 900 window)", lambda r: _ms(r["draw"], 0), "-"),
]


def _ms(timing: dict, digits: int) -> str:
    return f"{timing['median_ms']:.{digits}f} / {timing['max_ms']:.{digits}f} ms"


def viewer_table(columns: list[tuple[str, dict]]) -> str:
    """One column per run of ``benchmarks.interactive``: (heading, its JSON)."""
    lines = [
        "| measure | " + " | ".join(h for h, _ in columns) + " | target |",
        "|" + " --- |" * (len(columns) + 2),
    ]
    for label, cell, target in VIEWER_ROWS:
        lines.append(f"| {label} | " + " | ".join(cell(r) for _, r in columns) + f" | {target} |")
    return "\n".join(lines)


def _e(x: float) -> str:
    """1.2e-08 -> 1.2e-8."""
    mantissa, exponent = f"{x:.1e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def _method(method: str) -> str:
    if method.startswith("edge flips and collapses"):
        return "flips and collapses"
    if method.startswith("isotropic remeshing"):
        return "local remeshing"
    return method


def slivers_table(data: dict) -> str:
    """``benchmarks.slivers``'s repairs by ``fix_slivers`` (distances relative to the
    bounding-box diagonal)."""
    lines = [
        "| mesh | vertices | repair | triangles changed | below quality 0.05 | worst quality "
        "| largest vertex move / surface distance | time |",
        "|" + " --- |" * 8,
    ]
    for r in data["fix_slivers"]:
        before, after = r["worst_quality"]
        lines.append(
            f"| {r['mesh']} | {r['vertices']} | {_method(r['method'])} "
            f"| {r['triangles_changed']} of {r['triangles_before']} "
            f"| {r['below_0.05'][0]} -> {r['below_0.05'][1]} | {_e(before)} -> {after:.2g} "
            f"| {_e(r['max_vertex_shift'])} / {_e(r['max_deviation'])} "
            f"| {r['seconds']:.{2 if r['seconds'] < 1 else 1}f} s |"
        )
    return "\n".join(lines)


def curved_table(data: dict) -> str:
    """``benchmarks.curved``: exact spectra of curved meshes with thin parts."""
    lines = [
        "| mesh | vertices | operator | modes | exact s | exact MB |",
        "|" + " --- |" * 6,
    ]
    for r in data["rows"]:
        lines.append(
            f"| {r['mesh']} | {r['vertices']} | {r['operator']} | {r['k']} "
            f"| {r['exact_seconds']:.1f} | {r['exact_peak_mb']} |"
        )
    return "\n".join(lines)


def _find(rows: list[dict], **fields) -> dict | None:
    """The first row whose values match ``fields``, or None."""
    return next((r for r in rows if all(r.get(k) == v for k, v in fields.items())), None)


def growth_table(data: dict) -> str:
    """``benchmarks.growth``: seconds and peak memory of the exact solve against mesh
    size per operator, then the fitted growth exponents."""
    rows = data["rows"]
    sizes = sorted({r["vertices"] for r in rows})
    head = "| operator | " + " | ".join(f"{n:,}".replace(",", " ") for n in sizes)
    lines = [head + " | time exponent | memory exponent |", "|" + " --- |" * (len(sizes) + 3)]
    for fit in data["fits"]:
        op = fit["operator"]
        cells = []
        for n in sizes:
            r = _find(rows, operator=op, vertices=n)
            if r is None:
                cells.append("-")
            elif "refused" in r:
                cells.append("refused (memory)")
            else:
                mb = f"{r['peak_mb']:,}".replace(",", " ")
                cells.append(f"{r['seconds']:.1f} s, {mb} MB")
        lines.append(
            f"| {LABELS.get(op, op)} | "
            + " | ".join(cells)
            + f" | {fit['time_exponent']:.2f} | {fit['memory_exponent']:.2f} |"
        )
    return "\n".join(lines)


def _thousands(value: float) -> str:
    return f"{value:,.0f}".replace(",", " ")


def memory_check_table(more_modes: dict, curved: dict) -> str:
    """The memory check's predictions (:meth:`OperatorInfo.predicted_peak_mb`, what the
    viewer and the command line refuse by) beside the measured peaks of exact solves it
    was not fitted to: other mode counts (``growth_k300``) and a curved mesh
    (``curved``)."""
    from modalviewer.core.operators import operator_info

    lines = [
        "| mesh | operator | vertices | modes | measured peak | predicted | measured / predicted |",
        "|" + " --- |" * 7,
    ]
    runs = [("plate", r, r.get("peak_mb")) for r in more_modes["rows"]]
    runs += [(r["mesh"], r, r.get("exact_peak_mb")) for r in curved["rows"]]
    for mesh, r, peak in runs:
        if peak is None:
            continue
        info = operator_info(r["operator"])  # these runs kept their factors in core
        predicted = info.predicted_peak_mb(r["vertices"], r["k"], out_of_core=False)
        lines.append(
            f"| {mesh} | {LABELS.get(r['operator'], r['operator'])} | {r['vertices']} "
            f"| {r['k']} | {_thousands(peak)} MB | {_thousands(predicted)} MB "
            f"| {peak / predicted:.2f} |"
        )
    return "\n".join(lines)


def big_solves_table(data: dict) -> str:
    """``benchmarks.memory``: big exact solves with the factor in core and out of core,
    beside the memory check's prediction for the same choice."""
    from modalviewer.core.operators import operator_info

    lines = [
        "| mesh | operator | vertices | modes | memory limit | factor | Krylov basis "
        "| seconds | measured peak | predicted | largest residual | Mass-orthonormality "
        "| largest eigenvalue difference |",
        "|" + " --- |" * 13,
    ]
    for r in data["rows"]:
        if r.get("compared_with"):
            difference = f"{r['largest_relative_difference']:.1e} against {r['compared_with']}"
        else:
            difference = "(the reference)"
        info = operator_info(r["operator"])
        ooc, single = bool(r["factor_out_of_core"]), bool(r.get("basis_float32"))
        predicted = info.predicted_peak_mb(
            r["vertices"], r["k"], out_of_core=ooc, basis_float32=single
        )
        limit = "half the machine" if r["limit_mb"] == "none" else f"{r['limit_mb']} MB"
        factor = f"{_thousands(r['factor_mb'])} MB {'in a file' if ooc else 'in core'}"
        lines.append(
            f"| {r['mesh']} | {LABELS.get(r['operator'], r['operator'])} | {r['vertices']} "
            f"| {r['k']} | {limit} | {factor} | {'single' if single else 'double'} precision "
            f"| {r['seconds']:.0f} | {_thousands(r['peak_mb'])} MB | {_thousands(predicted)} MB "
            f"| {r['max_residual']:.1e} | {r['mass_orthonormality']:.1e} | {difference} |"
        )
    return "\n".join(lines)


def factor_memory_table(data: dict) -> str:
    """``benchmarks.factor_memory``: the factor's memory in core and out of core, the
    plates the laws are fitted to and curved meshes beside the laws' predictions."""
    from modalviewer.core.operators import operator_info

    lines = [
        "| mesh | operator | vertices | in core (law) | out of core (law) |",
        "|" + " --- |" * 5,
    ]
    rows = [(f"plate {r['grid']} x {r['grid']}", r) for r in data["plates"]]
    rows += [(r["mesh"], r) for r in data["curved"]]
    for mesh, r in rows:
        law = operator_info(r["operator"]).factor_memory
        n = r["vertices"]
        lines.append(
            f"| {mesh} | {LABELS.get(r['operator'], r['operator'])} | {n} "
            f"| {_thousands(r['in_core_mb'])} MB ({_thousands(law.in_core_mb(n))}) "
            f"| {_thousands(r['out_of_core_mb'])} MB ({_thousands(law.out_of_core_mb(n))}) |"
        )
    return "\n".join(lines)


def million_table(data: dict) -> str:
    """``benchmarks.million``: the viewer's window on a million vertices."""
    n = f"{data['vertices']:,}".replace(",", " ")
    lines = [
        "| step | seconds | what the viewer did | longest event-loop gap "
        "| computing process peak |",
        "| --- | --- | --- | --- | --- |",
        f"| open and draw {n} vertices | {data['open_and_draw_s']:.1f} | - | - | - |",
    ]
    r = data["laplacian"]
    what = r["status"][-1].rstrip(".") if r["status"] else ""
    lines.append(
        f"| {LABELS.get(r['operator'], r['operator'])}, {data['k']} modes "
        f"| {r['on_screen_s']:.0f} | {what} | {r['longest_event_loop_gap_ms']:.0f} ms "
        f"| {r['child_peak_mb_so_far'] / 1024:.1f} GB |"
    )
    pick = data["pick_and_distance_map_s"]
    lines.append(f"| pick and threshold map of the heat kernel distance | {pick:.1f} | - | - | - |")
    return "\n".join(lines)


def scale_figures(data: dict) -> str:
    """The README's performance figures: the largest mesh of ``benchmarks.growth`` per
    operator, the exact solve, as a short table."""
    rows = [r for r in data["rows"] if "seconds" in r]
    n = max(r["vertices"] for r in rows)
    lines = [
        f"| {n:,} vertices, {data['k']} modes | exact |".replace(",", " ", 2),
        "| --- | --- |",
    ]
    for op in dict.fromkeys(r["operator"] for r in rows):
        r = _find(rows, operator=op, vertices=n)
        cell = "-" if r is None else f"{r['seconds']:.0f} s, {r['peak_mb'] / 1024:.1f} GB"
        lines.append(f"| {LABELS.get(op, op)} | {cell} |")
    return "\n".join(lines)


def big_solves_figures(data: dict) -> str:
    """The README's memory figures: ``benchmarks.memory``'s runs, short."""
    lines = [
        "| mesh, 3D shells | modes | factor | Krylov basis | time | peak memory |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for r in data["rows"]:
        where = "out of core" if r["factor_out_of_core"] else "in core"
        basis = "single precision" if r.get("basis_float32") else "double precision"
        lines.append(
            f"| {r['mesh']} ({r['vertices']:,} vertices) | {r['k']} | {where} | {basis} "
            f"| {r['seconds']:.0f} s | {r['peak_mb'] / 1024:.1f} GB |".replace(",", " ")
        )
    return "\n".join(lines)


#: Every generated table: its name in the page's markers -> (JSON files, the table).
def correspondence_table(data: dict) -> str:
    """Functional maps on three bases (``benchmarks.correspondence``): the mean and median
    geodesic error of each basis, descriptor and refinement."""
    lines = [
        "| basis | descriptors | modes | mean error | median error | map s |",
        "|" + " --- |" * 6,
    ]
    for r in data["rows"]:
        modes = str(r["k"])
        if r["zoomout"] is not None:
            modes += f" -> {r['zoomout']} (ZoomOut, {r['zoomout_step']} a step)"
        lines.append(
            f"| {LABELS.get(r['basis'], r['basis'])} | {r['descriptors'].upper()} | {modes} "
            f"| {r['mean_error']:.3f} | {r['median_error']:.3f} | {r['map_seconds']:.1f} |"
        )
    return "\n".join(lines)


TABLES = {
    "readers": (["readers"], benchmark_table("readers")),
    "out-of-core-threads": (["out_of_core_threads"], benchmark_table("out_of_core_threads")),
    "first-modes": (["first_modes"], benchmark_table("first_modes")),
    "slicing": (["slicing"], benchmark_table("slicing")),
    "spectra": (["latest"], lambda: spectra_table(load("latest"))),
    "paper": (["latest"], lambda: paper_table(load("latest"))),
    "stages": (["latest"], lambda: stage_table(load("latest"))),
    "viewer": (
        [
            "interactive_130k_shells",
            "interactive_130k_modified_dirichlet",
            "interactive_130k_modified_dirichlet_desktop",
        ],
        lambda: viewer_table(
            [
                ("shells", load("interactive_130k_shells")),
                ("E_D^N", load("interactive_130k_modified_dirichlet")),
                ("E_D^N, desktop view", load("interactive_130k_modified_dirichlet_desktop")),
            ]
        ),
    ),
    "slivers": (["slivers"], lambda: slivers_table(load("slivers"))),
    "curved": (["curved"], lambda: curved_table(load("curved"))),
    "growth": (["growth"], lambda: growth_table(load("growth"))),
    "scale": (["growth"], lambda: scale_figures(load("growth"))),
    "million": (["million"], lambda: million_table(load("million"))),
    "big-solves": (["memory"], lambda: big_solves_table(load("memory"))),
    "memory-figures": (["memory"], lambda: big_solves_figures(load("memory"))),
    "factor-memory": (["factor_memory"], lambda: factor_memory_table(load("factor_memory"))),
    "correspondence": (["correspondence"], lambda: correspondence_table(load("correspondence"))),
    "memory": (
        ["growth_k300", "curved"],
        lambda: memory_check_table(load("growth_k300"), load("curved")),
    ),
}

README_TABLES = ("scale", "memory-figures")
"""The tables marked in README.md (the others are on the performance page)."""


def render(name: str) -> str:
    """The table ``name`` of TABLES, as Markdown."""
    return TABLES[name][1]()


def fill(text: str) -> str:
    """``text`` with every marked block replaced by its table made now."""

    def replace(match: re.Match) -> str:
        name = match.group(2)
        if name not in TABLES:
            raise KeyError(f"no benchmark table named {name!r} (known: {', '.join(TABLES)})")
        return f"{match.group(1)}{render(name)}\n{match.group(4)}"

    return MARKED.sub(replace, text)


#: The operators' names in the plots' legends.
LABELS = {
    "laplacian": "Laplacian",
    "shells": "3D shells",
    "modified_dirichlet": "E_D^N",
    "shells_normal": "normal shells",
}


def _axes(ax, ylabel: str, title: str, vertices) -> None:
    """Log-log axes with the meshes' vertex counts as the x ticks and plain numbers."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xticks(sorted(set(vertices)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:,.0f}".replace(",", " ")))
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.yaxis.set_major_locator(LogLocator(subs=(1, 2, 5)))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda y, _: f"{y:g}"))
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("vertices")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)


def _legend(fig, ax) -> None:
    """One legend for both panels, right of them."""
    fig.legend(*ax.get_legend_handles_labels(), loc="outside right upper", fontsize=7.5)


def _series(ax, rows: list[dict], key, label: str, style: str, color) -> None:
    """One line of ``key(row)`` (None: no point) against the rows' vertex counts."""
    points = sorted((r["vertices"], key(r)) for r in rows if key(r) is not None)
    if points:
        x, y = zip(*points, strict=True)
        ax.plot(x, y, style, color=color, label=label, markersize=5)


def spectra_plot(rows: list[dict], path: Path) -> Path:
    """``make bench``'s 300-mode rows: eigensolver time and peak memory against the
    number of vertices, per operator, beside plain scipy (the baseline) where it ran."""
    import matplotlib.pyplot as plt

    fig, (t_ax, m_ax) = plt.subplots(1, 2, figsize=(8.6, 3.3), layout="constrained")
    for i, op in enumerate(sorted({r["operator"] for r in rows})):
        mine = [r for r in rows if r["operator"] == op and r["k"] == 300]
        color = f"C{i}"
        name = LABELS.get(op, op)
        _series(t_ax, mine, lambda r: r["eigen_s"], name, "o-", color)
        _series(t_ax, mine, lambda r: r.get("baseline_eigen_s"), f"{name}, scipy", "s--", color)
        _series(m_ax, mine, lambda r: r["peak_mb"], name, "o-", color)
        _series(m_ax, mine, lambda r: r.get("baseline_peak_mb"), f"{name}, scipy", "s--", color)
    vertices = [r["vertices"] for r in rows]
    _axes(t_ax, "eigenproblem (s)", "300 modes: time", vertices)
    _axes(m_ax, "peak memory (MB)", "300 modes: peak memory", vertices)
    _legend(fig, t_ax)
    return _save(fig, path)


def growth_plot(data: dict, path: Path) -> Path:
    """``benchmarks.growth``: time and peak memory of the exact solve against mesh size,
    per operator."""
    import matplotlib.pyplot as plt

    rows = [r for r in data["rows"] if "seconds" in r]
    fig, (t_ax, m_ax) = plt.subplots(1, 2, figsize=(8.6, 3.3), layout="constrained")
    for i, op in enumerate(dict.fromkeys(r["operator"] for r in rows)):
        mine = [r for r in rows if r["operator"] == op]
        label = LABELS.get(op, op)
        _series(t_ax, mine, lambda r: r["seconds"], label, "o-", f"C{i}")
        _series(m_ax, mine, lambda r: r["peak_mb"], label, "o-", f"C{i}")
    vertices = [r["vertices"] for r in rows]
    _axes(t_ax, "time (s)", f"{data['k']} modes: time", vertices)
    _axes(m_ax, "peak memory (MB)", f"{data['k']} modes: peak memory", vertices)
    _legend(fig, t_ax)
    return _save(fig, path)


def _save(fig, path: Path) -> Path:
    import matplotlib.pyplot as plt

    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


#: Every generated plot: its name in the page's markers -> (JSON files, draw to a path).
PLOTS_MADE = {
    "spectra": (["latest"], lambda path: spectra_plot(load("latest"), path)),
    "growth": (["growth"], lambda path: growth_plot(load("growth"), path)),
}

#: The text under each plot's image on the HTML page.
PLOT_CAPTIONS = {
    "spectra": "Eigenproblem time and peak memory against mesh size, 300 modes "
    "(benchmarks/results/latest.json; dashed: plain scipy).",
    "growth": "Exact solve: time and peak memory from 10k to 1M vertices, 100 modes "
    "(benchmarks/results/growth.json).",
}


def draw_plots(folder: Path = PLOTS) -> list[Path]:
    """Draw every plot of PLOTS_MADE into ``folder`` (``<name>.png``)."""
    import matplotlib

    matplotlib.use("Agg")
    return [draw(folder / f"{name}.png") for name, (_, draw) in PLOTS_MADE.items()]


def with_plots(text: str) -> str:
    """``text`` with every ``<!-- plot: name -->`` line replaced by its image."""

    def replace(match: re.Match) -> str:
        name = match.group(1)
        if name not in PLOTS_MADE:
            raise KeyError(f"no benchmark plot named {name!r} (known: {', '.join(PLOTS_MADE)})")
        return (
            f":::{{figure}} _generated/plots/{name}.png\n:alt: {PLOT_CAPTIONS[name]}\n\n"
            f"{PLOT_CAPTIONS[name]}\n:::"
        )

    return PLOT_MARK.sub(replace, text)


def _builder_inited(app) -> None:
    draw_plots()


def _source_read(app, docname: str, source: list[str]) -> None:
    if "<!-- table: " in source[0]:
        source[0] = fill(source[0])
    if "<!-- plot: " in source[0]:
        source[0] = with_plots(source[0])


def _outdated(app, env, added, changed, removed) -> list[str]:
    """Pages with tables are read again on every build: the JSON results may have changed."""
    return [name for name in env.found_docs if name == "performance" and name not in changed]


def setup(app):
    app.connect("builder-inited", _builder_inited)
    app.connect("source-read", _source_read)
    app.connect("env-get-outdated", _outdated)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}


def main() -> int:
    for page in (PAGE, README):
        text = page.read_text()
        new = fill(text)
        if new != text:
            page.write_text(new)
            print(f"wrote {page.relative_to(ROOT)}")
    for path in draw_plots():
        print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
