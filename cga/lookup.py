"""Where a CGA path points: CityEngine looks a project path up in the rule's folder, its
project's ``assets/`` and each folder above; a path computed from strings (``prefix + x +
suffix``) names every file that matches."""

from __future__ import annotations

from pathlib import Path


def _roots(folder: Path) -> list[Path]:
    """Where CityEngine would look for a project path: the rule's folder, its project's
    ``assets/`` and the project itself, then each folder above (for ``/Project/...`` paths)."""
    out = [folder, folder / "assets", folder.parent / "assets", folder.parent]
    out += [p for p in folder.parents if p not in out]
    return out


def find(text: str, folder: Path) -> Path | None:
    """The file a CGA path names, looked up around ``folder``; None when nowhere."""
    rel = text.replace("\\", "/")
    parts = [p for p in rel.split("/") if p not in ("", ".")]
    if not parts or ".." in parts:
        return None
    tries = [parts]
    if rel.startswith("/") and len(parts) > 1:
        tries.append(parts[1:])  # "/Project/assets/x.obj": the project's own name dropped
        if len(parts) > 2 and parts[1] in ("assets", "rules"):
            tries.append(parts[2:])
    for root in _roots(folder):
        for p in tries:
            candidate = root.joinpath(*p)
            if candidate.is_file():
                return candidate
    return None


def like(prefix: str, suffix: str, folder: Path, most: int = 64) -> list[str]:
    """The CGA paths of the files that start with ``prefix`` and end with ``suffix`` in the
    first folder around ``folder`` that holds any (a path computed as prefix + x + suffix)."""
    head, _, start = prefix.replace("\\", "/").rpartition("/")
    for root in _roots(folder):
        where = root / head if head else root
        if not head.strip("/") and head:
            continue
        if not where.is_dir():
            continue
        names = sorted(
            f.name
            for f in where.iterdir()
            if f.is_file() and f.name.startswith(start) and f.name.lower().endswith(suffix.lower())
        )
        if names:
            return [f"{head}/{name}" if head else name for name in names[:most]]
    return []
