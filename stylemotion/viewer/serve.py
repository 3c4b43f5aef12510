"""Serve a written viewer folder on 127.0.0.1 with the standard library's static file server."""

from __future__ import annotations

import errno
import functools
import os
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer

from stylemotion.io.errors import UserInputError


class PortInUseError(UserInputError, OSError):
    """The port asked for is taken on 127.0.0.1."""


class _QuietHandler(SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args) -> None:  # noqa: A002 - the standard library's signature
        pass


def bind(port: int, host: str = "127.0.0.1") -> ThreadingHTTPServer:
    """A server bound to ``host:port`` (``port`` 0: a free one) serving the current folder until
    :func:`serve_folder` points it at the viewer; bound first so a taken port fails before anything is written.

    Raises:
        PortInUseError: naming the port.
    """
    try:
        return ThreadingHTTPServer((host, port), _QuietHandler)
    except OSError as exc:
        if exc.errno == errno.EADDRINUSE:
            raise PortInUseError(exc.errno, f"port {port} on {host} is in use; choose another --port "
                                            f"(--port 0 picks a free one)") from None
        raise


def serve_folder(server: ThreadingHTTPServer, folder: str | os.PathLike) -> None:
    """Serve ``folder`` with ``server`` until interrupted."""
    server.RequestHandlerClass = functools.partial(_QuietHandler, directory=os.fspath(folder))
    with server:
        server.serve_forever()


def url(server: ThreadingHTTPServer) -> str:
    host, port = server.server_address[:2]
    return f"http://{host}:{port}/index.html"
