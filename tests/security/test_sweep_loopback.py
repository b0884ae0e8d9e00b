"""A local sweep's Ray listens on loopback only: every listening socket of the Ray processes
the sweep's own start function launches (GCS, raylet with its object manager, workers, the
agents) is bound to 127.0.0.1 (or its IPv4-mapped IPv6 form), none to a wildcard or a routable
address.  Nothing is sent anywhere: the sockets are only listed (psutil)."""

from __future__ import annotations

import ipaddress
import os

import pytest

ray = pytest.importorskip("ray")
psutil = pytest.importorskip("psutil")

from sim_core import sweep  # noqa: E402


def _listening(root: psutil.Process) -> list[tuple[int, str, str, int]]:
    """(pid, name, address, port) of every listening TCP socket of ``root`` and its
    descendants."""
    out = []
    for p in [root, *root.children(recursive=True)]:
        try:
            out += [(p.pid, p.name(), c.laddr.ip, c.laddr.port)
                    for c in p.net_connections("inet") if c.status == psutil.CONN_LISTEN]
        except psutil.Error:
            pass
    return out


def _loopback(ip: str) -> bool:
    addr = ipaddress.ip_address(ip.split("%")[0])
    mapped = getattr(addr, "ipv4_mapped", None)
    return (mapped or addr).is_loopback


@pytest.mark.slow
def test_a_local_sweeps_ray_listens_on_loopback_only():
    if ray.is_initialized():
        pytest.skip("a Ray of another test runs in this process")
    rt, started = sweep._start_ray(None, 1)
    assert started
    try:
        @rt.remote
        def pid():
            return os.getpid()
        worker = rt.get(pid.remote())              # a worker process is up
        sockets = _listening(psutil.Process())
        assert len(sockets) >= 3, sockets           # GCS, raylet, a worker at least
        assert worker in {s[0] for s in sockets}    # the worker's own gRPC server is listed
        exposed = [s for s in sockets if not _loopback(s[2])]
        assert not exposed, f"Ray listens beyond loopback: {exposed}"
        assert rt.util.get_node_ip_address() == sweep.LOOPBACK
    finally:
        rt.shutdown()
