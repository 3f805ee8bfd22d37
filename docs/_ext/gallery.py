"""The gallery page, made by running the scripts of ``examples/gallery`` at build time.

Each script is a short program using the public API: a docstring (a title underlined
with ``=``, then a paragraph or two of explanation) and code that writes one or more PNGs
into the current folder with the viewer's own off-screen renderer.  At the start of a
build (Sphinx's ``builder-inited`` event) every script is run in a fresh temporary
folder; its PNGs and what it printed go to ``docs/_generated/gallery/<script>/``, together
with the SHA-256 of the script's text.  A script whose hash is unchanged is not run again,
so a rebuild after editing one example runs only that one (``rm -rf docs/_generated``
runs them all).  A script that fails, or writes no PNG, is a build warning, so an error
under ``make docs`` (``-W``).

``docs/_generated/gallery.inc`` (included by ``docs/gallery.rst``) gets, per script: the
docstring as text, the code after it as a literal block, what it printed, and the PNGs,
after a list of links to the examples.

Run as a script, it runs the examples that changed and writes the page source::

    .venv/bin/python docs/_ext/gallery.py
"""

from __future__ import annotations

import ast
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCRIPTS = ROOT / "examples" / "gallery"
OUT = ROOT / "docs" / "_generated" / "gallery"
PAGE_INCLUDE = ROOT / "docs" / "_generated" / "gallery.inc"

#: Seconds one example may take before it counts as failed.
TIMEOUT = 300


@dataclass
class Example:
    """One script of the gallery and what running it made."""

    script: Path
    docstring: str
    code: str
    images: list[Path] = field(default_factory=list)
    output: str = ""
    seconds: float | None = None  # None: taken from the cache
    error: str | None = None

    @property
    def name(self) -> str:
        return self.script.stem


def scripts(folder: Path = SCRIPTS) -> list[Path]:
    """The gallery's scripts, in the order of their names."""
    return sorted(p for p in folder.glob("*.py") if not p.name.startswith("_"))


def split(source: str) -> tuple[str, str]:
    """(docstring, the code after it) of a script's text."""
    module = ast.parse(source)
    doc = ast.get_docstring(module, clean=True)
    if doc is None:
        raise ValueError("a gallery script starts with a docstring (its title and text)")
    first = module.body[0]
    code = "\n".join(source.splitlines()[first.end_lineno :]).strip("\n")
    return doc, code


def digest(source: str) -> str:
    return hashlib.sha256(source.encode()).hexdigest()


def pictures(folder: Path) -> list[Path]:
    """The pictures a script wrote in ``folder``: PNGs and GIF animations."""
    return sorted([*folder.glob("*.png"), *folder.glob("*.gif")])


def run(script: Path, out_root: Path = OUT, force: bool = False) -> Example:
    """Run ``script`` in a temporary folder unless its output for the same text is in
    ``out_root``; returns the example with its images (copied to ``out_root/<name>``)."""
    source = script.read_text()
    doc, code = split(source)
    example = Example(script, doc, code)
    out = out_root / script.stem
    stamp = out / "hash"
    if not force and stamp.is_file() and stamp.read_text().strip() == digest(source):
        example.images = pictures(out)
        log = out / "output.txt"
        example.output = log.read_text() if log.is_file() else ""
        return example
    env = dict(os.environ)
    env.setdefault("QT_QPA_PLATFORM", "offscreen")
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    with tempfile.TemporaryDirectory(prefix=f"gallery-{script.stem}-") as tmp:
        started = time.perf_counter()
        try:
            result = subprocess.run(
                [sys.executable, str(script)],
                cwd=tmp,
                env=env,
                capture_output=True,
                text=True,
                timeout=TIMEOUT,
            )
        except subprocess.TimeoutExpired:
            example.error = f"took longer than {TIMEOUT} s"
            return example
        example.seconds = time.perf_counter() - started
        if result.returncode != 0:
            example.error = f"exit status {result.returncode}:\n{result.stderr[-2000:]}"
            return example
        images = pictures(Path(tmp))
        if not images:
            example.error = "wrote no PNG"
            return example
        if out.exists():
            shutil.rmtree(out)
        out.mkdir(parents=True)
        example.images = [Path(shutil.copy2(p, out / p.name)) for p in images]
        example.output = result.stdout
        (out / "output.txt").write_text(result.stdout)
        stamp.write_text(digest(source) + "\n")
    return example


def _indent(text: str, prefix: str = "   ") -> list[str]:
    return [prefix + line if line.strip() else "" for line in text.splitlines()]


def page_source(examples: list[Example], docs: Path = ROOT / "docs") -> str:
    """reStructuredText of the examples, for ``docs/gallery.rst`` to include."""
    lines = [f"- :ref:`gallery-{ex.name}`" for ex in examples] + [""]
    for ex in examples:
        lines += [f".. _gallery-{ex.name}:", ""]
        lines += ex.docstring.splitlines() + [""]
        rel = ex.script.relative_to(ROOT).as_posix() if ex.script.is_relative_to(ROOT) else ""
        if rel:
            lines += [f"``{rel}``:", ""]
        lines += [".. code-block:: python", ""] + _indent(ex.code) + [""]
        if ex.output.strip():
            lines += ["It prints:", "", ".. code-block:: text", ""]
            lines += _indent(ex.output.rstrip()) + [""]
        for image in ex.images:
            path = os.path.relpath(image, docs).replace(os.sep, "/")
            lines += [f".. image:: {path}", f"   :alt: {image.stem.replace('_', ' ')}", ""]
    return "\n".join(lines)


def build(out_root: Path = OUT, include: Path = PAGE_INCLUDE, log=print) -> list[Example]:
    """Run the examples that changed and write the page's include file (only if its
    text changed); returns the examples."""
    examples = []
    for script in scripts():
        ex = run(script, out_root)
        if ex.error:
            log(f"gallery: {script.relative_to(ROOT)} failed: {ex.error}")
        elif ex.seconds is not None:
            log(f"gallery: ran {script.name} in {ex.seconds:.1f} s")
        examples.append(ex)
    text = page_source([ex for ex in examples if not ex.error])
    if not include.is_file() or include.read_text() != text:
        include.parent.mkdir(parents=True, exist_ok=True)
        include.write_text(text)
    return examples


def _builder_inited(app) -> None:
    from sphinx.util import logging

    logger = logging.getLogger(__name__)
    examples = build(log=logger.info)
    for ex in examples:
        if ex.error:
            logger.warning(f"gallery example {ex.script.name} failed: {ex.error}")


def _outdated(app, env, added, changed, removed) -> list[str]:
    """The gallery page is read again on every build: its include may have changed."""
    return ["gallery"] if "gallery" in env.found_docs and "gallery" not in changed else []


def setup(app):
    app.connect("builder-inited", _builder_inited)
    app.connect("env-get-outdated", _outdated)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}


def main() -> int:
    examples = build()
    failed = [ex for ex in examples if ex.error]
    print(f"wrote {PAGE_INCLUDE.relative_to(ROOT)} ({len(examples) - len(failed)} examples)")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
