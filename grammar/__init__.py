"""The .bgr language front end: parser, syntax tree, checks, error messages and formatter."""
