"""The README's library example runs as written (from the repository root)."""

import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_readme_library_example_runs(tmp_path):
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## The library") :]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    cwd = os.getcwd()
    os.chdir(ROOT)
    try:
        namespace: dict = {}
        code = code.replace('"spot_shells.npz"', repr(str(tmp_path / "spot_shells.npz")))
        exec(compile(code, "README.md", "exec"), namespace)
    finally:
        os.chdir(cwd)
    assert namespace["d"].shape == (namespace["mesh"].n_vertices,)
    assert (tmp_path / "spot_shells.npz").is_file()
