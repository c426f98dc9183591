"""The .bgr standard library: modules imported as ``import stdlib.NAME as alias``."""
