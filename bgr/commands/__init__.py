"""The ``bgr`` command's subcommands, one module each.

Every module here has ``add_parser(commands)``, which declares the command's arguments on the
argparse subparsers, and ``run(args) -> int``, which runs it and returns the exit status.
``bgr/cli.py`` only lists them and dispatches.  They import the toolkit's heavy modules (numpy,
the interpreter) inside ``run``, so ``bgr check`` and ``bgr --help`` stay quick.  ``common.py``
holds the exit statuses and argument types all of them share, ``options.py`` the lot, budget and
memory options of the commands that derive or read data.
"""
