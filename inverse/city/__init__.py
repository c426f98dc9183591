"""City-scale proceduralization: an unstructured 3D city in, a grammar of component types out.

The pipeline of Martinovic-style city proceduralization (../shared/seeds/
city-scale-proceduralization.txt): read the city (:mod:`.read`), cut each building into
components between horizontal cut planes (:mod:`.cuts`), fit boxes and feature vectors, cluster
components into types (:mod:`.types`), cluster types into a parse tree (:mod:`.tree`) and write
the grammar with the types' meshes as assets (:mod:`.emit`).
"""
