import os

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import pytest  # noqa: E402


@pytest.fixture
def previews_pay(monkeypatch):
    """Make every request with "Preview first" get a preview, whatever its size (the
    predictor would give small test meshes none)."""
    from modalviewer.viewer import model as model_module

    def plan(key, n_vertices):
        return model_module.PreviewPlan(True, 0.0, 1e9, 0.0, 1.0)

    monkeypatch.setattr(model_module, "preview_plan", plan)
    return plan
