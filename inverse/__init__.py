"""Inverse modules that write .bgr grammars from data: Build-by-Number face schemas (schema/,
``bgr infer --kind schema``), city-scale proceduralization (city/, ``--kind city``),
structure-preserving retargeting of box hierarchies (boxes/, ``bgr retarget`` and
``--kind boxes``) and style sheets of textured buildings (style/, ``--kind style`` and
``bgr restyle``), and buildings from photographs (image/: a rectified façade photograph with
``--kind facade``, a building from one photograph and its outline with ``--kind image``).

Each module has the same shape: it reads its data, models it, emits a grammar's syntax tree
(printed by the formatter), and its ``command.py`` is the command-line side."""
