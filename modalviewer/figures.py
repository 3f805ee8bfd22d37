"""``modalviewer figures -o DIR``: rebuild the paper's figures on the demo meshes.

Every image is made by the viewer's own export (off-screen window), so it shows what a
user of the viewer sees.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

ASSETS = Path(__file__).resolve().parents[1] / "assets"


def build_figures(out_dir, progress=print) -> list[Path]:
    from .cli import _window

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    app, win = _window((900, 700))
    made: list[Path] = []

    def save(name: str, obj=None) -> None:
        path = out / f"{name}.png"
        (obj or win).export_screenshot(path)
        made.append(path)
        progress(f"wrote {path} (PNG, paper figure)")

    # Fig. 1: folded plate, Laplacian / E_D^N / shells normal, same mode index
    win.open_mesh(ASSETS / "demo_folded_plate.obj")
    state = win.state
    state.set_isolines(10)
    compare = win.open_comparison(["laplacian", "modified_dirichlet", "shells_normal"])
    compare.show_mode(5)
    save("fig1_folded_plate_modes", compare)
    compare.close()
    # Fig. 3: double torus, Laplacian vs E_D^N
    win.open_mesh(ASSETS / "demo_double_torus.obj")
    compare = win.open_comparison(["laplacian", "modified_dirichlet"])
    compare.show_mode(3)
    save("fig3_double_torus_modes", compare)
    compare.close()
    # Fig. 4: a vibration mode at its peak, soft and stiff membrane
    for membrane in (0.01, 100.0):
        state.set_compute_settings(membrane=membrane)
        win.compute("shells", k=16, wait=True)
        state.set_shell_coloring("magnitude")
        win.show_mode(8)
        state.set_animation(amplitude=30)
        win.animation_frame(np.pi / 2)
        save(f"fig4_vibration_membrane_{membrane:g}")
    state.set_compute_settings(membrane=1.0)
    state.set_shell_coloring("normal")
    # Figs. 5 and 7: vibration distance on spot, continuous and two thresholds
    win.open_mesh(ASSETS / "spot.obj")
    win.compute("shells", k=100, wait=True)
    win.pick_vertex(2000)
    win.show_distance("vibration", display="continuous")
    save("fig5_vibration_distance_continuous")
    for q in (0.1, 0.25):
        win.show_distance("vibration", display="threshold", threshold=q)
        save(f"fig5_vibration_distance_threshold_{q:g}")
    # Fig. 6: bent hand, vibration vs heat kernel distance from a fingertip
    tips = json.loads((ASSETS / "demo_landmarks.json").read_text())["demo_hand_bent"]
    win.open_mesh(ASSETS / "demo_hand_bent.obj")
    win.compute("shells", k=100, wait=True)
    win.compute("laplacian", k=100, wait=True)
    win.pick_vertex(tips["finger2"])
    win.show_distance("vibration", display="threshold", threshold=0.3)
    compare = win.open_comparison(["vibration", "hks"])
    save("fig6_hand_vibration_vs_hks", compare)
    compare.close()
    # Fig. 9: vibration distance from the same fingertip, full mesh and coarse-to-fine
    tips_straight = json.loads((ASSETS / "demo_landmarks.json").read_text())["demo_hand"]
    for coarse in (False, True):
        win.open_mesh(ASSETS / "demo_hand.obj")
        state.set_compute_settings(coarse=coarse)
        win.compute("shells", k=100, wait=True)
        win.pick_vertex(tips_straight["finger1"])
        win.show_distance("vibration", display="continuous")
        save(f"fig9_hand_vibration_distance_{'coarse_to_fine' if coarse else 'full'}")
    state.set_compute_settings(coarse=False)
    # Fig. 8: feature signature on the machined part at three scales, and curvature
    win.open_mesh(ASSETS / "demo_machined_part.obj")
    win.compute("modified_dirichlet", k=100, wait=True)
    state.set_display(distance_kind="feature")
    for sample in (10, 50, 90):
        win.show_signature(sample)
        save(f"fig8_feature_signature_scale{sample}")
    win.show_curvature()
    save("fig8_curvature")
    # Fig. 10: bumpy plate, feature signature
    win.open_mesh(ASSETS / "demo_bumpy_plate.obj")
    win.compute("modified_dirichlet", k=100, wait=True)
    win.show_signature(30)
    save("fig10_bumpy_plate_feature_signature")
    win.close()
    return made
