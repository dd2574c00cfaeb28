"""The page's web server: the static page, JSON routes over `ServedRobot`, and every error as one JSON line
({"error": "..."}, 4xx for a bad request, 503 when the data folder cannot complete, 500 for a defect),
never a traceback.

Routes: GET / (the page), GET /api/vocabulary, POST /api/complete, /api/answer, /api/execute, /api/listen
(a WAV body), GET /api/animation/{id}.gif.
"""

from __future__ import annotations

import ipaddress
import logging
import socket
from collections.abc import Callable
from pathlib import Path
from typing import Literal

from fastapi import FastAPI, Query, Request
from fastapi.concurrency import run_in_threadpool
from fastapi.exceptions import RequestValidationError
from fastapi.responses import FileResponse, JSONResponse, Response
from fastapi.staticfiles import StaticFiles
from pydantic import BaseModel, ConfigDict, Field
from starlette.exceptions import HTTPException

from lmcr.errors import LMCRError, one_line
from lmcr.lexicon import load_lexicon
from lmcr.robot.reply import error_outcome, say
from lmcr.scorers.registry import COMPLETION_METHOD
from lmcr.serve.robot import MAX_AUDIO_BYTES, MAX_OBJECTS, Pending, RequestError, ServedRobot, read_reply
from lmcr.workspace import Workspace

STATIC = Path(__file__).with_name("static")
EXAMPLE = {"instruction": "pour me some water", "objects": ["water", "cup", "plate", "scissors"]}
log = logging.getLogger("lmcr.serve")


class ServeError(LMCRError, RuntimeError):
    """The server cannot start: the address is taken or cannot be bound."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class SceneRequest(_Strict):
    instruction: str
    objects: list[str]
    seed: int = Field(0, ge=0, le=2**31 - 1)  # the random layout of the objects on the table


class ExecuteRequest(SceneRequest):
    answer: dict[str, str] | None = None  # role -> object, what a person answered


class PendingBody(_Strict):
    kind: Literal["choose", "offer"]
    role: str
    choices: list[str] = Field(min_length=1)
    allowed: list[str]
    question: str
    tries: int = Field(1, ge=1)


class AnswerRequest(_Strict):
    reply: str
    pending: PendingBody


def _error(status: int, message: object) -> JSONResponse:
    return JSONResponse({"error": one_line(message, 500)}, status_code=status)


def _invalid(exc: RequestValidationError) -> str:
    """The first problem of a request body pydantic refused, as one line naming the field."""
    first = exc.errors()[0] if exc.errors() else {}
    where = ".".join(str(part) for part in first.get("loc", ())[1:])
    if first.get("type") == "json_invalid":
        return "the request body is not JSON"
    if not where:
        return "the request body must be a JSON object (Content-Type: application/json)"
    return f"{where}: {first.get('msg', 'invalid')}"


def _install_errors(app: FastAPI) -> None:
    @app.exception_handler(RequestValidationError)
    async def invalid(request: Request, exc: RequestValidationError) -> JSONResponse:
        return _error(422, _invalid(exc))

    @app.exception_handler(HTTPException)
    async def http(request: Request, exc: HTTPException) -> JSONResponse:
        return _error(exc.status_code, exc.detail)

    @app.exception_handler(LMCRError)
    async def lmcr(request: Request, exc: LMCRError) -> JSONResponse:
        # ValueError: the request's input (instruction, objects, answer, audio); else the data folder's state
        response = _error(422 if isinstance(exc, ValueError) else 503, exc)
        outcome = error_outcome(exc)
        if "error_kind" in outcome:  # the robot did not understand: it says so, as in `lmcr robot`
            response = JSONResponse({"error": one_line(exc, 500), "reply": say(outcome)}, response.status_code)
        return response

    # A middleware, not a handler of Exception: Starlette re-raises after such a handler, and the server
    # would print the traceback.
    @app.middleware("http")
    async def defect(request: Request, call_next):
        try:
            return await call_next(request)
        except Exception as exc:
            log.error("%s %s: %s: %s", request.method, request.url.path, type(exc).__name__, one_line(exc, 300))
            return _error(500, f"internal error ({type(exc).__name__}: {one_line(exc, 200)}); please report it")


def create_app(ws: Workspace, method: str = COMPLETION_METHOD, corpus: str = "all") -> FastAPI:
    """The page and its API for the data folder of `ws`, completing with `method` on `corpus`'s
    checkpoints. Nothing is loaded until the first request that needs the models."""
    robot = ServedRobot(ws, method, corpus)
    app = FastAPI(title="LMCR", docs_url=None, redoc_url=None, openapi_url=None)
    app.state.robot = robot
    _install_errors(app)
    app.mount("/static", StaticFiles(directory=STATIC), name="static")

    @app.get("/", include_in_schema=False)
    def page() -> FileResponse:
        return FileResponse(STATIC / "index.html", media_type="text/html")

    @app.get("/api/vocabulary")
    def vocabulary() -> dict:
        lex = load_lexicon()
        return {
            "objects": list(lex.objects),
            "max_objects": MAX_OBJECTS,
            "example": EXAMPLE,
            "predicates": {name: spec.sentence for name, spec in lex.predicates.items()},
            "method": method,
            "corpus": corpus,
            "data_dir": str(ws.data_dir),
        }

    @app.post("/api/complete")
    def complete(body: SceneRequest) -> dict:
        return robot.complete(body.instruction, body.objects, body.seed)

    @app.post("/api/answer")
    def answer(body: AnswerRequest) -> dict:
        return read_reply(body.reply, Pending(**body.pending.model_dump()))

    @app.post("/api/execute")
    def execute(body: ExecuteRequest) -> dict:
        return robot.execute(body.instruction, body.objects, body.seed, body.answer)

    @app.post("/api/listen")
    async def listen(request: Request, objects: str = Query("", max_length=2000)) -> dict:
        declared = request.headers.get("content-length", "")
        if declared.isdigit() and int(declared) > MAX_AUDIO_BYTES:
            raise RequestError(
                f"the recording is {int(declared) / 2**20:.1f} MiB; the limit is {MAX_AUDIO_BYTES / 2**20:.0f} MiB"
            )
        audio = await request.body()
        labels = [o for o in objects.split(",") if o.strip()]
        return await run_in_threadpool(robot.listen, audio, labels)

    @app.get("/api/animation/{key}.gif")
    def animation(key: str) -> Response:
        data = robot.animations.get(key)
        if data is None:
            raise HTTPException(404, f"no animation {key[:40]!r} (the server keeps the last few runs)")
        return Response(data, media_type="image/gif", headers={"Cache-Control": "no-store"})

    return app


def bind(host: str, port: int) -> socket.socket:
    """A listening socket on host:port (port 0: any free port), or a one-line ServeError."""
    try:
        family = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)[0][0]
        return socket.create_server((host, port), family=family)
    except OSError as exc:  # taken, not an address of this machine, not a host name
        raise ServeError(f"cannot listen on {host}:{port}: {exc.strerror or one_line(exc)}") from exc


def is_loopback(host: str) -> bool:
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return host == "localhost"


def serve(
    ws: Workspace,
    host: str = "127.0.0.1",
    port: int = 8000,
    method: str = COMPLETION_METHOD,
    corpus: str = "all",
    say: Callable[[str], None] = print,
) -> None:
    """Serve the page on host:port until interrupted (Ctrl-C or SIGTERM); `say` gets the address."""
    import uvicorn

    sock = bind(host, port)
    name, bound = sock.getsockname()[:2]
    shown = f"[{name}]" if ":" in name else name
    say(f"LMCR page at http://{shown}:{bound}/ (data folder {ws.data_dir}; Ctrl-C stops it)")
    if not is_loopback(host):
        say(f"warning: {host} is not a loopback address; anyone who can reach this machine can use the page")
    server = uvicorn.Server(uvicorn.Config(create_app(ws, method, corpus), log_level="warning"))
    try:
        server.run(sockets=[sock])
    finally:
        sock.close()
