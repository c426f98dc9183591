"""Inverse modules that write .bgr grammars from data: Build-by-Number face schemas (schema/,
``bgr infer --kind schema``), city-scale proceduralization (city/, ``--kind city``) and
structure-preserving retargeting of box hierarchies (boxes/, ``bgr retarget`` and
``--kind boxes``). Style sheets and photographs (``--kind style``, ``--kind image``) are not
written yet."""
