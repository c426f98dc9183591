"""``bgr serve FILE.bgr``: the model beside the text, re-derived on every save.

A small ASGI app (starlette, run by uvicorn; chosen over aiohttp for its test client, which
exercises the routes without a socket, and because uvicorn's websockets are the ones the page
needs) on 127.0.0.1 by default:

* ``/`` the page (``editor/static/``: three.js, vendored); ``/model.glb`` the model;
* ``/ws`` a websocket pushing each new model as it is derived (a JSON message, then the GLB's
  bytes), or the error that stopped it;
* ``/state`` the file, its attrs (with their ``@Range``/``@Enum`` metadata) and the settings;
* ``/settings`` (POST) new attr values, seed or lot feature: derived again;
* ``/pick?x=&y=&z=`` the terminal at a point of the model: its label, rule path and attrs;
* ``/command`` the ``bgr derive`` command line of the current settings.

The grammar's folder and the folders of the files it imports are watched (watchfiles): a save
derives again, in the worker of :mod:`.derivation` (the latest request wins, a runaway one is
stopped). A derivation that fails leaves the last good model shown and the error beside it.
Only the page's own static files and the derived model are served (no other path of the
machine), and a request whose Host is not this machine's is refused (a web page elsewhere
cannot reach the server through a DNS name it controls).
"""

from __future__ import annotations

import asyncio
import json
import shlex
from contextlib import asynccontextmanager
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from starlette.applications import Starlette
from starlette.middleware import Middleware
from starlette.middleware.trustedhost import TrustedHostMiddleware
from starlette.requests import Request as HttpRequest
from starlette.responses import FileResponse, JSONResponse, Response
from starlette.routing import Mount, Route, WebSocketRoute
from starlette.staticfiles import StaticFiles
from starlette.websockets import WebSocket, WebSocketDisconnect

from . import analysis
from .derivation import Deriver, Outcome, Request

STATIC = Path(__file__).resolve().parent / "static"
LOCAL_HOSTS = ["127.0.0.1", "localhost", "::1", "[::1]", "testserver"]


@dataclass
class Session:
    """What the server shows: the settings, the last good model and the last error."""

    request: Request
    version: int = 0  # of the last good model
    model: Outcome | None = None
    error: Outcome | None = None
    watched: set[Path] = field(default_factory=set)
    sockets: set[WebSocket] = field(default_factory=set)
    derivations: int = 0  # how many ran (tests count them)


class Server:
    """The session and the work it schedules; one per ``bgr serve``."""

    def __init__(self, request: Request, timeout: float | None = None) -> None:
        self.session = Session(request)
        self.deriver = Deriver() if timeout is None else Deriver(timeout)
        self._pending: Request | None = None
        self._wake: asyncio.Event | None = None
        self._tasks: list[asyncio.Task] = []

    # ---- scheduling: the latest request wins ----------------------------------------------

    def schedule(self, request: Request | None = None) -> None:
        """Derive ``request`` (or the current settings again) as soon as possible; a
        derivation still running for older settings is stopped."""
        self._pending = request or self.session.request
        if self._wake is not None:
            self._wake.set()
        self.deriver.stop()

    async def _runner(self) -> None:
        assert self._wake is not None
        while True:
            await self._wake.wait()
            self._wake.clear()
            request, self._pending = self._pending, None
            if request is None:
                continue
            outcome = await asyncio.to_thread(self.deriver.run, request)
            if outcome is None or self._pending is not None:
                continue  # stopped for newer settings: derive those
            self.session.derivations += 1
            self.session.request = request
            await self._publish(outcome)

    async def _publish(self, outcome: Outcome) -> None:
        session = self.session
        if outcome.errors:
            session.error = outcome
            message = {"type": "error", "errors": outcome.errors}
        else:
            session.model, session.error = outcome, None
            session.version += 1
            message = self._model_message()
            self._watch_imports()
        for socket in list(session.sockets):
            try:
                await self._send(socket, message)
            except Exception:  # a closed page: forget it
                session.sockets.discard(socket)

    async def _send(self, socket: WebSocket, message: dict) -> None:
        """A message to a page; a model's is followed by the GLB itself, as bytes."""
        await socket.send_json(message)
        if message["type"] == "model" and self.session.model is not None:
            await socket.send_bytes(self.session.model.glb)

    def _model_message(self) -> dict:
        model = self.session.model
        assert model is not None
        return {
            "type": "model",
            "version": self.session.version,
            "triangles": model.triangles,
            "terminals": len(model.terminals),
            "seconds": round(model.seconds, 3),
            "warnings": model.warnings,
        }

    # ---- watching the files -------------------------------------------------------------

    def _watch_imports(self) -> None:
        """The folders of the grammar and of every file it imports."""
        folders = {Path(self.session.request.path).resolve().parent}
        checked = analysis.check(_read(self.session.request.path), self.session.request.path)
        seen: set[int] = set()

        def walk(grammar) -> None:
            if id(grammar) in seen:
                return
            seen.add(id(grammar))
            folders.add(Path(analysis.real_path(grammar)).resolve().parent)
            for sub in grammar.imports.values():
                walk(sub)

        if checked.grammar is not None:
            walk(checked.grammar)
        self.session.watched = folders

    async def _watcher(self) -> None:
        from watchfiles import awatch

        while True:
            folders = set(self.session.watched)
            stop = asyncio.Event()
            watching = asyncio.ensure_future(self._until_watched_changes(folders, stop))
            try:
                async for changes in awatch(*folders, stop_event=stop, debounce=50, step=20):
                    if any(Path(p).suffix in _WATCHED for _, p in changes):
                        self.schedule()
            finally:
                watching.cancel()

    async def _until_watched_changes(self, folders: set[Path], stop: asyncio.Event) -> None:
        while self.session.watched == folders:
            await asyncio.sleep(0.5)
        stop.set()

    # ---- the app ------------------------------------------------------------------------

    def app(self, hosts: list[str] | None = None) -> Starlette:
        @asynccontextmanager
        async def lifespan(app):
            self._wake = asyncio.Event()
            self.session.watched = {Path(self.session.request.path).resolve().parent}
            self._tasks = [
                asyncio.create_task(self._runner()),
                asyncio.create_task(self._watcher()),
            ]
            self.schedule()
            try:
                yield
            finally:
                for task in self._tasks:
                    task.cancel()
                self.deriver.stop()

        routes = [
            Route("/", self.page),
            Route("/state", self.state),
            Route("/model.glb", self.model),
            Route("/settings", self.settings, methods=["POST"]),
            Route("/pick", self.pick),
            Route("/command", self.command),
            WebSocketRoute("/ws", self.socket),
            Mount("/static", StaticFiles(directory=STATIC), name="static"),
        ]
        middleware = [Middleware(TrustedHostMiddleware, allowed_hosts=hosts or LOCAL_HOSTS)]
        return Starlette(routes=routes, middleware=middleware, lifespan=lifespan)

    async def page(self, request: HttpRequest) -> Response:
        return FileResponse(STATIC / "index.html", headers={"Cache-Control": "no-store"})

    async def state(self, request: HttpRequest) -> Response:
        session = self.session
        settings = session.request
        metadata = {}
        checked = analysis.check(_read(settings.path), settings.path)
        if checked.grammar is not None:
            from bgr.grammar.annotations import attr_metadata

            metadata = attr_metadata(checked.grammar)
        return JSONResponse(
            {
                "file": Path(settings.path).name,
                "attrs": _plain(metadata),
                "values": settings.attrs,
                "seed": settings.seed,
                "lot": settings.lot,
                "features": _features(settings.lot),
                "feature": settings.feature,
                "version": session.version,
                "model": None if session.model is None else self._model_message(),
                "errors": [] if session.error is None else session.error.errors,
            }
        )

    async def model(self, request: HttpRequest) -> Response:
        model = self.session.model
        if model is None:
            return Response("no model yet", status_code=404)
        return Response(
            model.glb, media_type="model/gltf-binary", headers={"Cache-Control": "no-store"}
        )

    async def settings(self, request: HttpRequest) -> Response:
        try:
            body = await request.json()
            current = self.session.request
            changed = replace(
                current,
                seed=int(body.get("seed", current.seed)),
                attrs=_attrs(body.get("attrs", current.attrs)),
                feature=_feature(body.get("feature", current.feature)),
            )
        except (ValueError, TypeError, json.JSONDecodeError) as e:
            return JSONResponse({"ok": False, "error": str(e)[:200]}, status_code=400)
        self.schedule(changed)
        return JSONResponse({"ok": True})

    async def pick(self, request: HttpRequest) -> Response:
        model = self.session.model
        if model is None or model.faces is None or not len(model.faces):
            return JSONResponse({"found": False})
        try:
            point = np.array([float(request.query_params[k]) for k in "xyz"])
        except (KeyError, ValueError):
            return JSONResponse({"found": False, "error": "give x, y and z"}, status_code=400)
        row = _nearest_terminal(model, point)
        terminal = model.terminals[row]
        return JSONResponse(
            {"found": True, **terminal, "attrs": self.session.request.attrs, "row": row}
        )

    async def command(self, request: HttpRequest) -> Response:
        settings = self.session.request
        words = ["bgr", "derive", settings.path, "--seed", str(settings.seed)]
        for name, value in settings.attrs.items():
            words += ["--set", f"{name}={_text(value)}"]
        if settings.lot:
            words += ["--lot", settings.lot]
        words += ["-o", f"{Path(settings.path).stem}.glb"]
        return JSONResponse({"command": shlex.join(words)})

    async def socket(self, websocket: WebSocket) -> None:
        await websocket.accept()
        self.session.sockets.add(websocket)
        try:
            if self.session.model is not None:
                await self._send(websocket, self._model_message())
            if self.session.error is not None:
                await websocket.send_json({"type": "error", "errors": self.session.error.errors})
            while True:
                await websocket.receive_text()  # the page says nothing; this waits for it to go
        except WebSocketDisconnect:
            pass
        finally:
            self.session.sockets.discard(websocket)


_WATCHED = {".bgr", ".obj", ".glb", ".gltf", ".png", ".jpg", ".jpeg", ".geojson", ".json"}


def _read(path: str) -> str:
    try:
        return Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return ""


def _nearest_terminal(model: Outcome, point: np.ndarray) -> int:
    """The terminal row of the triangle nearest to ``point`` (its centre, then the closest of
    the few nearest centres by the true point-to-triangle distance)."""
    import trimesh

    assert model.vertices is not None and model.faces is not None
    assert model.face_terminal is not None
    triangles = model.vertices[model.faces]
    centres = triangles.mean(axis=1)
    near = np.argsort(np.linalg.norm(centres - point, axis=1))[:64]
    closest = trimesh.triangles.closest_point(triangles[near], np.repeat([point], len(near), 0))
    best = near[int(np.argmin(np.linalg.norm(closest - point, axis=1)))]
    return int(model.face_terminal[best])


def _attrs(values) -> dict:
    if not isinstance(values, dict):
        raise TypeError("attrs is an object of name: value")
    out = {}
    for name, value in values.items():
        if not isinstance(name, str) or not isinstance(value, (bool, int, float, str)):
            raise TypeError(f"attr {name!r}: a number, a string or true/false")
        out[name] = value
    return out


def _feature(value) -> int | None:
    return None if value is None or value == "" else int(value)


def _text(value) -> str:
    return ("true" if value else "false") if isinstance(value, bool) else str(value)


def _features(lot: str | None) -> list[str]:
    """The names of a GeoJSON lot file's features (for the page's lot picker)."""
    if not lot or not lot.lower().endswith((".geojson", ".json")):
        return []
    try:
        data = json.loads(Path(lot).read_text(encoding="utf-8"))
        features = data.get("features", [])
        return [
            str(f.get("id") or (f.get("properties") or {}).get("name") or f"feature {i}")
            for i, f in enumerate(features)
        ]
    except (OSError, ValueError, AttributeError):
        return []


def _plain(value):
    """Metadata as JSON can hold it (tuples to lists)."""
    return json.loads(json.dumps(value, default=str))
