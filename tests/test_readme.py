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


def _slug(heading: str) -> str:
    """The anchor a Markdown heading gets on GitHub."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def test_readme_and_docs_links_resolve():
    """Every relative link and image in README.md and docs/*.md names a file that exists,
    and every #anchor a heading (or an <a id>) of the page it points to."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    assert len(pages) >= 9, "README.md and the docs pages"
    anchors = {}
    for page in pages:
        text = page.read_text()
        prose = re.sub(r"```.*?```", "", text, flags=re.S)
        found = {_slug(h) for h in re.findall(r"^#+ (.*)$", prose, re.M)}
        anchors[page.resolve()] = found | set(re.findall(r'<a id="([^"]+)"', text))
    bad = []
    for page in pages:
        prose = re.sub(r"```.*?```", "", page.read_text(), flags=re.S)
        for link in re.findall(r"\]\(([^)\s]+)\)", prose):
            if link.startswith(("http://", "https://", "mailto:")):
                continue
            path, _, fragment = link.partition("#")
            target = (page.parent / path).resolve() if path else page.resolve()
            if not target.exists():
                bad.append(f"{page.name}: {link} (no such file)")
            elif fragment and target.suffix == ".md" and fragment not in anchors[target]:
                bad.append(f"{page.name}: {link} (no such heading)")
    assert not bad, bad


def test_readme_images_are_exports_in_screenshots():
    """The README shows pictures made by the app's export, kept in screenshots/."""
    images = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", (ROOT / "README.md").read_text())
    assert images
    for image in images:
        assert image.startswith("screenshots/") and (ROOT / image).is_file(), image


def test_readme_keeps_the_two_setup_commands():
    text = (ROOT / "README.md").read_text()
    assert "make run" in text and "make test" in text
