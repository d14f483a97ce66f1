"""The twin's hand channel: a scripted hand sent to ``teachfit robot twin`` over loopback TCP.

The twin listens on ``127.0.0.1:1339`` (:data:`HAND_PORT`, beside libfranka's 1337 and the
gripper's 1338; loopback only, as every socket of the twin). A client sends one line
``TEACHFIT-HAND 1``, the guide's CSV text (:mod:`teachfit.robot.franka.hand`) and a line
``END``; the twin parses it with the same checks and answers one line: ``OK`` (the hand starts
at the physics' next tick, on the twin's own clock) or ``ERROR <why>``. A real robot has no
such channel: :func:`send_guide` then says so.
"""

from __future__ import annotations

import socket
import threading
from collections.abc import Callable

from teachfit.core.errors import TeachfitError
from teachfit.robot.franka.hand import MAX_BYTES, Guide, GuideError, parse_guide

HAND_PORT = 1339
MAGIC = "TEACHFIT-HAND 1"


def send_guide(host: str, guide: Guide, what: str = "--hand", timeout: float = 10.0) -> None:
    """Hand ``guide`` (named ``what`` in errors) to the twin on ``host`` (loopback);
    :class:`TeachfitError` if no twin's hand channel answers there or the twin refuses it."""
    body = f"{MAGIC}\n{guide.to_csv()}END\n".encode()
    try:
        with socket.create_connection((host, HAND_PORT), timeout=timeout) as conn:
            conn.sendall(body)
            reply = conn.makefile("r", encoding="utf-8").readline().strip()
    except OSError as exc:
        raise TeachfitError(
            f"{what}: nothing answers on {host}:{HAND_PORT} ({exc.strerror or exc}): a scripted "
            "hand guides only the twin (teachfit robot twin --no-realtime); on a real arm a "
            "person guides it, record without --hand"
        ) from None
    if reply != "OK":
        raise TeachfitError(f"{what}: the twin refused the guide: {reply or 'no answer'}")


class HandChannel:
    """The twin's side: a thread accepting guides on ``host:HAND_PORT`` and passing each to
    ``take`` (the simulator's :meth:`set_hand`). A context manager: stopped on exit."""

    def __init__(self, host: str, take: Callable[[Guide], None]) -> None:
        self.take = take
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            self._sock.bind((host, HAND_PORT))
        except OSError as exc:
            self._sock.close()
            raise TeachfitError(
                f"{host}:{HAND_PORT} (the twin's hand channel) is taken ({exc.strerror}): stop "
                "what listens there, then start the twin again"
            ) from None
        self._sock.listen(2)
        self._sock.settimeout(0.2)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="twin-hand", daemon=True)

    def __enter__(self) -> HandChannel:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)
        self._sock.close()

    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self._sock.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            with conn:
                conn.settimeout(5.0)
                conn.sendall((self._receive(conn) + "\n").encode())

    def _receive(self, conn: socket.socket) -> str:
        """Read one guide from ``conn`` and pass it on; the answer line."""
        data = b""
        try:
            while not data.endswith(b"\nEND\n"):
                chunk = conn.recv(65536)
                if not chunk or len(data) > MAX_BYTES:
                    return "ERROR the guide did not end with END or is over the size limit"
                data += chunk
        except OSError:
            return "ERROR the guide did not arrive in time"
        text = data.decode("utf-8", errors="replace")
        head, _, rest = text.partition("\n")
        if head.strip() != MAGIC:
            return f"ERROR not a guide (expected {MAGIC})"
        try:
            guide = parse_guide(rest[: -len("END\n")], "the guide")
        except GuideError as exc:
            return f"ERROR {exc}"
        self.take(guide)
        return "OK"
