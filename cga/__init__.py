"""``bgr import-cga``: CityEngine CGA rule files translated into .bgr grammars.

``parse`` reads CGA's syntax (cga.lark), ``translate`` turns the tree into bgr's syntax tree
(``bgr.grammar.nodes``) that the formatter prints, with a warning at the line and column of every
construct it could not carry over; ``files`` finds the assets and imported rule files beside the
CGA file and writes the results.
"""
