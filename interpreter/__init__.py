"""Derivation of .bgr grammars into meshes (issue 3; not written yet)."""
