"""Inverse modules that write .bgr grammars from data (not written yet)."""
