"""``modalviewer figures -o DIR``: rebuild the paper's figures on the demo meshes.

Every image is made by a :class:`~modalviewer.viewer.Viewer` and drawn off screen by the
viewer's own scene (no window, no Qt), so it shows what a user of the viewer sees.
"""

from __future__ import annotations

import json
from pathlib import Path

from .data import assets_dir

ASSETS = assets_dir()
FIGURE_SIZE = (900, 700)
"""Pixels of a single-view figure; comparisons are 480 x 480 per view."""


def build_figures(out_dir, progress=print) -> list[Path]:
    from .viewer import Viewer

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    viewer = Viewer()
    viewer.renderer(FIGURE_SIZE)
    state = viewer.state
    made: list[Path] = []

    def save(name: str, comparison=None) -> None:
        path = out / f"{name}.png"
        if comparison is None:
            viewer.export_screenshot(path, size=FIGURE_SIZE)
        else:
            viewer.export_comparison(comparison, path)
        made.append(path)
        progress(f"wrote {path} (PNG, paper figure)")

    try:
        # Fig. 1: folded plate, Laplacian / E_D^N / shells normal, same mode index
        viewer.open_mesh(ASSETS / "demo_folded_plate.obj")
        state.style.isolines = 10
        compare = viewer.comparison(["laplacian", "modified_dirichlet", "shells_normal"])
        compare.show_mode(5)
        save("fig1_folded_plate_modes", compare)
        # Fig. 3: double torus, Laplacian vs E_D^N
        viewer.open_mesh(ASSETS / "demo_double_torus.obj")
        compare = viewer.comparison(["laplacian", "modified_dirichlet"])
        compare.show_mode(3)
        save("fig3_double_torus_modes", compare)
        # Fig. 4: a vibration mode as the deformed shape over the rest shape's ghost,
        # soft and stiff membrane
        state.style.shell_coloring = "deformed"
        state.style.ghost = True
        for membrane in (0.01, 100.0):
            state.compute_settings.membrane = membrane
            viewer.compute("shells", k=16)
            viewer.show_mode(8)
            state.animation.amplitude = 30
            save(f"fig4_vibration_membrane_{membrane:g}")
        state.compute_settings.membrane = 1.0
        state.animation.amplitude = 40
        # Figs. 5 and 7: vibration distance on spot, continuous and two threshold maps
        # (marking a tenth and a quarter of the surface)
        viewer.open_mesh(ASSETS / "spot.obj")
        viewer.compute("shells", k=100)
        viewer.pick_vertex(2000)
        viewer.show_distance("vibration", display="continuous")
        save("fig5_vibration_distance_continuous")
        for share in (0.1, 0.25):
            viewer.show_distance("vibration", display="threshold", share=share)
            save(f"fig5_vibration_distance_threshold_{share:g}")
        # Fig. 6: bent hand, vibration vs heat kernel distance from a fingertip
        landmarks = json.loads((ASSETS / "demo_landmarks.json").read_text())
        viewer.open_mesh(ASSETS / "demo_hand_bent.obj")
        viewer.compute("shells", k=100)
        viewer.compute("laplacian", k=100)
        viewer.pick_vertex(landmarks["demo_hand_bent"]["finger2"])
        viewer.show_distance("vibration", display="threshold", share=0.1)
        save("fig6_hand_vibration_vs_hks", viewer.comparison(["vibration", "hks"]))
        # Fig. 9: vibration distance from a fingertip, full mesh and coarse-to-fine
        for coarse in (False, True):
            viewer.open_mesh(ASSETS / "demo_hand.obj")
            state.compute_settings.coarse = coarse
            viewer.compute("shells", k=100)
            viewer.pick_vertex(landmarks["demo_hand"]["finger1"])
            viewer.show_distance("vibration", display="continuous")
            save(f"fig9_hand_vibration_distance_{'coarse_to_fine' if coarse else 'full'}")
        state.compute_settings.coarse = False
        # Fig. 8: feature signature on the machined part at three scales, and curvature
        viewer.open_mesh(ASSETS / "demo_machined_part.obj")
        viewer.compute("modified_dirichlet", k=100)
        state.set_display(distance_kind="feature")
        for sample in (10, 50, 90):
            viewer.show_signature(sample)
            save(f"fig8_feature_signature_scale{sample}")
        viewer.show_curvature()
        save("fig8_curvature")
        # Fig. 10: bumpy plate, feature signature
        viewer.open_mesh(ASSETS / "demo_bumpy_plate.obj")
        viewer.compute("modified_dirichlet", k=100)
        viewer.show_signature(30)
        save("fig10_bumpy_plate_feature_signature")
    finally:
        viewer.close()
    return made
