"""Asset paths that still resolve once a model is written to another folder.

MuJoCo resolves a mesh, height field or skin file against ``meshdir`` and a texture file
against ``texturedir``, each relative to the model file's folder unless absolute. A model
written to an output folder keeps working when those two are rewritten as paths from the
output folder to the folders the files were found in (``<include>``d files need nothing:
the spec holds their contents, and the written MJCF is one file).
"""

from __future__ import annotations

import os
from pathlib import Path

import mujoco

__all__ = ["relocate_assets"]


def _has_files(elements: list[mujoco.MjsMesh] | list[mujoco.MjsTexture] | list[mujoco.MjsHField]) -> bool:
    return any(getattr(e, "file", "") for e in elements)


def _relocated(folder: str, source_dir: Path, out_dir: Path) -> str:
    found = Path(folder) if os.path.isabs(folder) else source_dir / folder
    rel = os.path.relpath(found.resolve(), out_dir.resolve())
    return rel if rel.endswith(os.sep) else rel + os.sep


def relocate_assets(
    spec: mujoco.MjSpec, source_dir: str | os.PathLike[str], out_dir: str | os.PathLike[str]
) -> list[str]:
    """Rewrite ``spec``'s meshdir and texturedir for a model written into ``out_dir``.

    Only the folders that file-based assets use are rewritten; the spec's own model folder
    becomes ``out_dir`` (writing the MJCF loads the assets from there).

    Args:
        spec: the spec to write (changed in place).
        source_dir: the folder the model was read from (``spec.modelfiledir``).
        out_dir: the folder it will be written to.

    Returns:
        One line per rewritten folder ('meshdir: assets/ -> ../model/assets/').
    """
    src, out = Path(source_dir), Path(out_dir)
    changes = []
    spec.modelfiledir = str(out.resolve()) + os.sep  # where MuJoCo resolves the new folders from
    mesh_files = _has_files(list(spec.meshes)) or _has_files(list(spec.hfields)) or _has_files(list(spec.skins))
    for attr, used in (("meshdir", mesh_files), ("texturedir", _has_files(list(spec.textures)))):
        if not used:
            continue
        old = getattr(spec, attr) or ""
        new = _relocated(old, src, out)
        if new != old:
            setattr(spec, attr, new)
            changes.append(f"{attr}: '{old}' -> '{new}'")
    return changes
