"""Live view: stream the running trials to the Foxglove app over the SDK's WebSocket server.

``python -m graspexp live=true [live_port=8765]`` starts one server per process on 127.0.0.1 (loopback
only) and every trial log's messages go to it as well as to the file, on the same topics; the app
connects with "Open connection" -> Foxglove WebSocket -> ``ws://127.0.0.1:8765``. Each trial starts its
clock at 0 (log time is simulation time). Off by default; when off no server is started.
"""

import foxglove

from graspexp.record.channels import Channels

HOST = "127.0.0.1"
_SERVERS: dict[int, tuple[foxglove.WebSocketServer, Channels]] = {}


class LiveViewError(RuntimeError):
    """The live-view server could not start (e.g. the port is taken): the job cannot run as asked."""


def live_channels(port: int) -> Channels:
    """The channels of this process's live server on 127.0.0.1:``port`` (started on first use).

    ``port=0`` lets the system pick a free port: :func:`live_port` tells which.
    """
    if port not in _SERVERS:
        context = foxglove.Context()
        try:
            server = foxglove.start_server(name="graspexp", host=HOST, port=port, context=context)
        except Exception as exc:  # the SDK raises a RuntimeError naming the OS error
            raise LiveViewError(
                f"live view: cannot listen on {HOST}:{port} ({exc}); pick a free port with live_port=N"
            ) from exc
        _SERVERS[port] = (server, Channels(context))
    return _SERVERS[port][1]


def live_port(port: int) -> int:
    """The port the server started by ``live_channels(port)`` listens on."""
    return _SERVERS[port][0].port


def stop_live(port: int) -> None:
    """Stop the server started by ``live_channels(port)`` (a later call starts a new one)."""
    server, _ = _SERVERS.pop(port)
    server.stop()
