"""The project's own references: every document a file cites is in the repository.

Papers are cited by author and year and listed in docs/references.md; MuJoCo facts the code
relies on are in docs/mujoco_notes.md. A citation of a document that a user of the
repository cannot open (a notes file kept elsewhere, a paper by an internal number) is a
failure, as is a bibliography entry that does not say how sure we are of it.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SOURCES = (".py", ".md", ".toml", ".c", ".h", ".txt", ".cfg")
SKIP = {".git", ".ruff_cache", ".mypy_cache", ".venv", "build", "dist", "__pycache__"}
REFERENCES = ROOT / "docs" / "references.md"


def _project_files() -> list[Path]:
    """Every text file of the project (not generated caches, not an installed build)."""
    found = []
    for path in ROOT.rglob("*"):
        parts = set(path.relative_to(ROOT).parts)
        if parts & SKIP or any(p.endswith(".egg-info") for p in parts) or not path.is_file():
            continue
        if path.suffix in SOURCES and path.name != "MUJOCO_LOG.TXT":
            found.append(path)
    return found


def test_every_cited_document_is_in_the_repository():
    # a document named in capitals (as a notes file kept beside the project would be) or by its
    # docs/ or benchmarks/ path
    named = re.compile(r"\b(?:(?:docs|benchmarks)/[\w./-]+\.md|[A-Z][A-Z_]{2,}\.md)\b")
    missing = []
    for path in _project_files():
        for m in named.finditer(path.read_text(encoding="utf-8", errors="replace")):
            cited = m.group(0)
            if "/" in cited and "{" not in cited:
                ok = (ROOT / cited).exists()
            else:
                ok = any(ROOT.rglob(cited))
            if not ok:
                missing.append(f"{path.relative_to(ROOT)}: {cited}")
    assert not missing, "cited but not in the repository:\n" + "\n".join(sorted(set(missing)))


def test_no_paper_is_named_by_an_internal_number():
    internal = re.compile(r"\b(?:seed )?paper \d{3}\b|\bseed paper\b", re.IGNORECASE)
    hits = [
        f"{p.relative_to(ROOT)}: {m.group(0)}"
        for p in _project_files()
        for m in internal.finditer(p.read_text(encoding="utf-8", errors="replace"))
    ]
    assert not hits, hits


def test_every_bibliography_entry_says_how_sure_we_are():
    text = REFERENCES.read_text(encoding="utf-8")
    entries = re.split(r"\n### ", text)[1:]
    assert len(entries) >= 20  # the laws, the mechanisms' papers, the bearings' papers, our measurements
    for entry in entries:
        title = entry.splitlines()[0]
        assert re.search(r"\[(checked|recalled|derived)", entry), f"{title}: no [checked], [recalled] or [derived]"


def test_the_papers_the_code_cites_are_in_the_bibliography():
    """Each author-year citation the package's modules make names an entry of docs/references.md."""
    text = REFERENCES.read_text(encoding="utf-8")
    cited = {
        "Lankarani and Nikravesh 1990",
        "Hunt and Crossley 1975",
        "Flores, Machado, Silva and Martins 2011",
        "Gonthier, McPhee, Lange and Piedbœuf 2004",
        "Hu and Guo 2015",
        "Hertz 1882",
        "Ambrósio 2002",
        "Flores and Ambrósio 2004",
        "Alok, Chaudhary and Guha 2020",
        "Zheng, Zhang and Wang 2018",
        "Flores, Ambrósio, Claro and Lankarani 2008",
        "Flores, Ambrósio, Claro and Lankarani 2009",
        "Flores, Leine and Glocker 2010",
    }
    code = "\n".join(p.read_text(encoding="utf-8") for p in _project_files() if p.suffix == ".py")
    for name in cited:
        assert f"### {name}" in text, name
    # the citations in the code use these exact spellings (a renamed entry would orphan them)
    used = [name for name in cited if name in code]
    assert len(used) >= 8, used
