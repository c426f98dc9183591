"""``bgr serve FILE.bgr``: a live preview in the browser, derived again on every save
(editor/serve.py; docs/cli.md)."""

from __future__ import annotations

import sys
from pathlib import Path

from ..grammar.errors import BgrError
from .common import EXIT_OK, EXIT_USAGE, count, set_values, whole


def add_parser(commands) -> None:
    p = commands.add_parser(
        "serve",
        help="show the model in a browser, derived again on every save",
        description="Serve a page that shows FILE's model (three.js), derives it again each "
        "time FILE or a file it imports is saved, shows errors with their line and keeps the "
        "last good model, and has a slider or field per attr, a seed box, a lot picker and "
        "click-to-identify. Bound to 127.0.0.1 unless --host says otherwise. Needs the "
        "optional extra: pip install 'bgr[serve]'.",
    )
    p.add_argument("file", metavar="FILE.bgr", help="the grammar to show")
    p.add_argument("--seed", type=whole, default=0, help="global random seed (default 0)")
    p.add_argument(
        "--set", action="append", default=[], metavar="NAME=VALUE", help="override an attr"
    )
    p.add_argument(
        "--lot",
        metavar="W,D|LOTS.geojson",
        help="the lot: W,D in metres (default 20,20) or GeoJSON footprints (the page picks one)",
    )
    p.add_argument("--port", type=count, default=8000, help="the port (default 8000)")
    p.add_argument(
        "--host",
        default="127.0.0.1",
        help="the address to listen on (default 127.0.0.1: this machine only)",
    )


def run(args) -> int:
    attrs = set_values(args.set)
    if isinstance(attrs, str):
        print(f"bgr serve: error: {attrs}", file=sys.stderr)
        return EXIT_USAGE
    if not Path(args.file).is_file():
        raise BgrError(f"{args.file}: no such file")
    try:
        import uvicorn

        from ..editor.derivation import Request
        from ..editor.serve import LOCAL_HOSTS, Server
    except ImportError as e:
        raise BgrError(
            f"bgr serve needs its optional extra ({e.name} is missing): pip install 'bgr[serve]'"
        ) from None
    request = Request(str(Path(args.file).resolve()), args.seed, attrs, args.lot)
    hosts = LOCAL_HOSTS if args.host in ("127.0.0.1", "localhost", "::1") else ["*"]
    app = Server(request).app(hosts)
    print(f"bgr serve: http://{args.host}:{args.port}/ (Ctrl-C stops it)", file=sys.stderr)
    uvicorn.run(app, host=args.host, port=args.port, log_level="warning")
    return EXIT_OK
