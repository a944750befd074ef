"""A calibration through a tls:// dask scheduler with two TLS workers on 127.0.0.1; a client
without the certificate authority's certificate is refused."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

import simgap
from simgap.cli import main
from simgap.errors import SimgapError
from simgap.executor import probe_scheduler
from tests.conftest import set_budget


def _openssl(*args, cwd):
    subprocess.run(["openssl", *args], cwd=cwd, check=True, capture_output=True)


def make_certificates(folder: Path, name: str) -> dict[str, Path]:
    """A certificate authority and one certificate it signed (scheduler, workers and client share it)."""
    folder.mkdir(parents=True, exist_ok=True)
    _openssl("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj", f"/CN={name}-ca",
             "-keyout", "ca.key", "-out", "ca.pem", cwd=folder)
    _openssl("req", "-newkey", "rsa:2048", "-nodes", "-subj", f"/CN={name}", "-keyout", "key.pem", "-out", "req.csr", cwd=folder)
    (folder / "san.ext").write_text("subjectAltName=IP:127.0.0.1,DNS:localhost\n")
    _openssl("x509", "-req", "-in", "req.csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial", "-days", "2",
             "-extfile", "san.ext", "-out", "cert.pem", cwd=folder)
    return {"ca": folder / "ca.pem", "cert": folder / "cert.pem", "key": folder / "key.pem"}


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def tls_cluster(tmp_path):
    if not shutil_which("openssl"):
        pytest.skip("openssl is not installed")
    certs = make_certificates(tmp_path / "certs", "simgap-test")
    tls = ["--tls-ca-file", str(certs["ca"]), "--tls-cert", str(certs["cert"]), "--tls-key", str(certs["key"])]
    port = _free_port()
    address = f"tls://127.0.0.1:{port}"
    bindir = Path(sys.executable).parent
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    procs = [subprocess.Popen([str(bindir / "dask"), "scheduler", "--protocol", "tls", "--host", "127.0.0.1", "--port", str(port),
                               "--no-dashboard", *tls], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=tmp_path)]
    for i in range(2):
        procs.append(subprocess.Popen([str(bindir / "dask"), "worker", address, "--nthreads", "1", "--no-dashboard", "--host", "127.0.0.1",
                                       "--local-directory", str(tmp_path / f"w{i}"), *tls],
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=tmp_path))
    from distributed import Client
    from distributed.security import Security

    security = Security(tls_ca_file=str(certs["ca"]), tls_client_cert=str(certs["cert"]), tls_client_key=str(certs["key"]),
                        require_encryption=True)
    deadline = time.monotonic() + 60
    while True:
        try:
            with Client(address, timeout="2s", security=security) as client:
                client.wait_for_workers(2, timeout=30)
            break
        except (OSError, TimeoutError):
            if time.monotonic() > deadline:
                raise
            time.sleep(0.5)
    yield address, certs
    for p in procs[::-1]:
        p.kill()
    for p in procs:
        p.wait(timeout=20)


def shutil_which(name):
    import shutil

    return shutil.which(name)


@pytest.mark.timeout(240)
def test_calibration_through_a_tls_scheduler(quickstart_text, write_workflow, tls_cluster, tmp_path):
    address, certs = tls_cluster
    text = set_budget(quickstart_text, 24, population=8)
    text = text.replace("execution:\n", f"execution:\n  scheduler: {address}\n  tls: {{ca: {certs['ca']}, cert: {certs['cert']}, key: {certs['key']}}}\n", 1)
    path = write_workflow(text)
    checked = CliRunner().invoke(main, ["check", str(path), "--no-simulate"])
    assert checked.exit_code == 0 and f"scheduler: {address} with 2 workers" in checked.output, checked.output
    result = CliRunner().invoke(main, ["run", str(path)])
    assert result.exit_code == 0, result.output
    assert f"2 dask workers ({address})" in result.output
    run = simgap.load_run(path.parent / "runs")
    assert len(run.evaluations) == 24 and (run.evaluations["status"] == "ok").all()

    # a client whose certificates another authority signed is refused, and so is one without any
    from distributed.security import Security

    rogue = make_certificates(tmp_path / "rogue", "someone-else")
    stranger = Security(tls_ca_file=str(rogue["ca"]), tls_client_cert=str(rogue["cert"]), tls_client_key=str(rogue["key"]),
                        require_encryption=True)
    with pytest.raises(SimgapError, match="cannot reach the dask scheduler"):
        probe_scheduler(address, stranger, timeout_s=3)
    with pytest.raises(Exception):
        probe_scheduler(address, None, timeout_s=3)

    # a missing certificate file is named at its key by check
    bad = write_workflow(text.replace(str(certs["key"]), str(tmp_path / "nope.pem")), "bad.yaml")
    out = CliRunner().invoke(main, ["check", str(bad), "--no-simulate"])
    assert out.exit_code == 2 and "execution.tls.key: no such file" in out.output, out.output


def test_plain_tcp_beyond_loopback_is_warned_about():
    from simgap.executor import is_loopback

    assert is_loopback("tcp://127.0.0.1:8786") and is_loopback("tcp://localhost:8786") and is_loopback("tcp://[::1]:8786")
    assert not is_loopback("tcp://10.0.0.5:8786") and not is_loopback("tcp://scheduler.example.org:8786")
