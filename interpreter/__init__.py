"""Derivation of .bgr grammars into meshes: the engine, its operations and geometry."""
