"""Inverse modules that write .bgr grammars from data: Build-by-Number face schemas (schema/,
``bgr infer --kind schema``), city-scale proceduralization (city/, ``--kind city``),
structure-preserving retargeting of box hierarchies (boxes/, ``bgr retarget`` and
``--kind boxes``) and style sheets of textured buildings (style/, ``--kind style`` and
``bgr restyle``). A procedural building from a photograph (``--kind image``) is not written
yet."""
