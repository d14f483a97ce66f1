"""A libfranka-protocol simulator confined to loopback: ``franky-sim`` (MuJoCo FR3) launched by us.

``python -m teachfit.robot.franka.sim [--push-file PATH]`` runs franky-sim's MuJoCo backend
with one FR3 on ``127.0.0.1`` (TCP 1337 robot, 1338 gripper), what ``franky-sim -s mujoco
--hostname 127.0.0.1`` runs, with two changes made before anything binds:

* **Loopback only.** franky-sim binds its TCP servers to the given hostname but its per-client
  UDP state socket to ``0.0.0.0`` (``FrankaServer._setup_udp_connection``; there is no option).
  This launcher patches :meth:`socket.socket.bind` *in its own process* so that an
  all-interfaces address becomes ``127.0.0.1`` and any other non-loopback address is refused
  (:func:`confine_to_loopback`). The patch is process-wide on purpose: whatever franky-sim or a
  library under it binds stays on loopback.
* **An external push** (optional, ``--push-file``): franky-sim offers no way to apply an external
  force, and it reports no external-wrench estimate (``O_F_ext_hat_K`` is always zero). Each tick
  a pre-step callback (franky-sim's ``register_pre_step_callback``) applies the force written in
  the file (``fx fy fz``, N, robot base frame; file absent = no push) to the hand at the
  end-effector point, and the state sent to the client reports it in libfranka's convention:
  ``O_F_ext_hat_K`` is the wrench the *robot exerts on the environment* (the negated push).
  That makes a pushed-arm test possible; it does not test a wrench estimator.

:class:`SimServer` starts this launcher as a separate process (the pylibfranka client blocks on
connect when the server shares its Python process), in its own process group, waits until it
is ready, and stops it by its PID and group.
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import ipaddress
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

from teachfit.core.errors import ConnectionLost

if TYPE_CHECKING:
    from _typeshed import ReadableBuffer

HOST = "127.0.0.1"
ROBOT_PORT = 1337
READY = "TEACHFIT-FRANKY-SIM-READY"

_original_bind = socket.socket.bind


def _loopback_bind(self: socket.socket, address: tuple[Any, ...] | str | ReadableBuffer) -> None:
    if self.family in (socket.AF_INET, socket.AF_INET6) and isinstance(address, tuple):
        host = address[0]
        if host in ("", "0.0.0.0", "::"):
            address = (HOST, *address[1:]) if self.family == socket.AF_INET else address
        elif not ipaddress.ip_address(socket.gethostbyname(host)).is_loopback:
            raise OSError(f"teachfit franky-sim launcher: refusing to bind {host!r} (not loopback)")
    _original_bind(self, address)


def confine_to_loopback() -> None:
    """Make every IPv4 bind of this process use loopback (all-interfaces -> 127.0.0.1)."""
    socket.socket.bind = _loopback_bind  # type: ignore[method-assign, assignment]  # patched


def _install_push(sim: Any, robot: Any, path: Path) -> None:
    """Apply the force in ``path`` to the hand each tick and report it as O_F_ext_hat_K."""
    import mujoco
    import numpy as np
    from franky_sim import franka_robot_server

    state: dict[str, Any] = {"force": np.zeros(3), "mtime": None, "tick": 0}
    model, data = sim.model, sim.data
    hand = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "robot0_hand")
    ee_offset = np.array([0.0, 0.0, 0.1034])  # hand frame -> franky-sim's EE (TCP) point

    def read_force() -> None:
        try:
            mtime = path.stat().st_mtime_ns
        except FileNotFoundError:
            state["force"], state["mtime"] = np.zeros(3), None
            return
        if mtime != state["mtime"]:
            text = path.read_text().split()
            if len(text) == 3:
                state["force"], state["mtime"] = np.array([float(v) for v in text]), mtime

    def pre_step(_sim: object) -> None:
        if state["tick"] % 20 == 0:
            read_force()
        state["tick"] += 1
        f = state["force"]
        point = data.xpos[hand] + data.xmat[hand].reshape(3, 3) @ ee_offset
        data.xfrc_applied[hand, :3] = f
        data.xfrc_applied[hand, 3:] = np.cross(point - data.xipos[hand], f)

    sim.register_pre_step_callback(pre_step)
    server_cls = franka_robot_server.FrankaRobotServer

    def state_bytes(self: Any) -> bytes:
        f = state["force"]
        ext = (-float(f[0]), -float(f[1]), -float(f[2]), 0.0, 0.0, 0.0)
        return self.robot_state.replace(O_F_ext_hat_K=ext).pack_state()

    server_cls._get_state_bytes = state_bytes
    del robot


#: why the simulator cannot start while something else listens on the robot's port
PORT_TAKEN = (
    f"{HOST}:{ROBOT_PORT} is taken (another Franka simulator or server listens there; "
    "libfranka's port cannot be changed): stop it, then start the simulator again"
)


def _refuse(why: str) -> NoReturn:
    """One line on stderr naming the port and the fix; exit status 2."""
    print(f"error: teachfit.robot.franka.sim: {why}", file=sys.stderr, flush=True)
    raise SystemExit(2)


def main(argv: list[str] | None = None) -> None:
    """Run franky-sim (MuJoCo, one FR3) on 127.0.0.1 until SIGTERM/SIGINT."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--push-file", type=Path, default=None)
    parser.add_argument(
        "--parent", type=int, default=None, help="end with this process (the one that started it)"
    )
    args = parser.parse_args(argv)
    if args.parent is not None:  # SIGTERM (a clean stop) if the starter dies without stopping us
        from teachfit.core.process import die_with_parent

        die_with_parent(args.parent, signal.SIGTERM)
    if not port_free(HOST, ROBOT_PORT):
        _refuse(PORT_TAKEN)
    confine_to_loopback()
    import franky_sim
    from franky_sim.mujoco_simulator import MujocoSimulator

    signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(KeyboardInterrupt()))
    with MujocoSimulator(enable_visualization=False) as sim, contextlib.ExitStack() as stack:
        robot = sim.add_robot()
        try:
            server = stack.enter_context(
                franky_sim.SimulationServer(sim, hostname_candidates=[HOST])
            )
        except OSError as exc:  # taken since the check above, or another bind failure
            _refuse(PORT_TAKEN if not port_free(HOST, ROBOT_PORT) else f"cannot listen: {exc}")
        if args.push_file is not None:
            _install_push(sim, robot, args.push_file)
        print(f"{READY} {robot.hostname}", flush=True)  # listening since the init
        try:
            server.run_forever()
        except KeyboardInterrupt:
            pass


class SimServer:
    """The launcher as a child process on 127.0.0.1, in its own process group.

    Parameters
    ----------
    push_file : path or None
        File through which a test applies an external push (see the module docstring).
    startup_timeout : float
        Seconds to wait for the server to print that it is ready and accept on port 1337.
    """

    #: the line the server prints once it listens; what it is, for messages
    ready = READY
    what = "franky-sim"

    def __init__(self, push_file: Path | None = None, startup_timeout: float = 60.0) -> None:
        self.push_file = push_file
        self.startup_timeout = startup_timeout
        self.host = HOST
        self.proc: subprocess.Popen[str] | None = None
        #: the server's last output lines (diagnostics)
        self.log: collections.deque[str] = collections.deque(maxlen=200)
        self._ready = threading.Event()

    def _drain(self, out: Iterable[str]) -> None:
        try:
            for line in out:
                self.log.append(line)
                if line.startswith(self.ready):
                    self._ready.set()
        except (OSError, ValueError):  # closed by stop()
            pass

    def start(self) -> SimServer:
        """Start the server process and wait until it listens (it prints READY)."""
        if not port_free(self.host, ROBOT_PORT):
            raise ConnectionLost(f"{self.host}:{ROBOT_PORT} is taken: another Franka server runs")
        self.proc = subprocess.Popen(
            self.command(),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            start_new_session=True,  # own process group: stopped as a group by its PID
        )
        deadline = time.monotonic() + self.startup_timeout
        self._ready.clear()
        # drain its output from the start (a full pipe would block the server), keep the tail
        threading.Thread(target=self._drain, args=(self.proc.stdout,), daemon=True).start()
        while not self._ready.wait(0.2):
            if self.proc.poll() is not None or time.monotonic() > deadline:
                break
        # READY is printed after the server listens. No probe connection here: franky-sim would
        # accept the probe as its one client and make the real client's connect time out.
        if not self._ready.is_set():
            self.stop()
            raise ConnectionLost(f"{self.what} did not start:\n" + "".join(list(self.log)[-20:]))
        return self

    def command(self) -> list[str]:
        """The server's command line (it ends with this process: ``--parent``)."""
        cmd = [sys.executable, "-m", "teachfit.robot.franka.sim", "--parent", str(os.getpid())]
        if self.push_file is not None:
            cmd += ["--push-file", str(self.push_file)]
        return cmd

    @property
    def pid(self) -> int | None:
        return None if self.proc is None else self.proc.pid

    def kill(self) -> None:
        """Kill the server at once (SIGKILL to its group): a robot that vanishes mid-run."""
        if self.proc is not None and self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait(timeout=10)

    def stop(self, timeout: float = 10.0) -> None:
        """Stop the server by its PID and process group (SIGTERM, then SIGKILL)."""
        proc, self.proc = self.proc, None
        if proc is None:
            return
        if proc.poll() is None:
            try:
                os.killpg(proc.pid, signal.SIGTERM)
                proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait(timeout=timeout)
            except ProcessLookupError:
                pass
        if proc.stdout is not None:
            proc.stdout.close()

    def __enter__(self) -> SimServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


def port_free(host: str, port: int) -> bool:
    """Whether nothing listens on ``host:port`` (a bind test: a probe connection would be
    taken by a franky-sim as its client)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind((host, port))
        except OSError:
            return False
    return True


if __name__ == "__main__":
    main()
