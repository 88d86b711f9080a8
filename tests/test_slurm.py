"""Slurm, for real: a single-node cluster from Debian's slurm-wlm and munge on this machine
(munged as the munge user on its own socket and key, slurmctld and slurmd in the
foreground with -f on a slurm.conf written here, state and spool under a temporary
directory), a sweep submitted as a job array, collected, and compared with the same sweep
run locally; then a run removed and resubmitted alone.

Needs root and the packages (.ci/run installs them). Under CI (CI set) a missing package
or a cluster that does not come up is a failure, never a skip."""

from __future__ import annotations

import json
import os
import pwd
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
from conftest import INPUTS

SWEEP = [sys.executable, "-m", "frictiondyn", "sweep"]
DAEMONS = ("munged", "slurmctld", "slurmd", "sbatch", "squeue", "sinfo")

ROOT = Path(__file__).resolve().parents[1]


def _unavailable(reason: str):
    if os.environ.get("CI"):
        pytest.fail(f"Slurm integration test cannot run in CI: {reason}")
    pytest.skip(reason)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _which(name: str) -> str | None:
    return shutil.which(name) or shutil.which(name, path="/usr/sbin:/usr/bin:/sbin:/bin")


def _wait(cond, timeout: float, what: str, logs=()):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if cond():
            return
        time.sleep(0.25)
    text = "\n".join(f"--- {p}:\n{Path(p).read_text()[-3000:]}" for p in logs if Path(p).exists())
    raise AssertionError(f"timed out after {timeout} s waiting for {what}\n{text}")


@pytest.fixture(scope="module")
def cluster():
    """A running single-node Slurm; yields the environment for its clients."""
    if os.geteuid() != 0:
        _unavailable("starting slurmctld, slurmd and munged needs root")
    missing = [d for d in DAEMONS if _which(d) is None]
    if missing:
        _unavailable(f"not installed: {missing} (apt-get install slurm-wlm munge)")
    try:
        munge_user = pwd.getpwnam("munge")
    except KeyError:
        _unavailable("no munge user (apt-get install munge)")
    base = Path(tempfile.mkdtemp(prefix="fd-slurm-"))
    base.chmod(0o755)  # munged (not root) must reach its folder
    mdir = base / "munge"
    mdir.mkdir(mode=0o700)
    key = mdir / "munge.key"
    key.write_bytes(os.urandom(1024))
    key.chmod(0o400)
    for p in (mdir, key):
        os.chown(p, munge_user.pw_uid, munge_user.pw_gid)
    sock = mdir / "munge.socket"
    host = socket.gethostname().split(".")[0]
    for d in ("state", "spool"):
        (base / d).mkdir()
    conf = base / "slurm.conf"
    template = (ROOT / "tools" / "slurm" / "single-node.conf.in").read_text()
    for mark, value in (("@HOST@", host), ("@DIR@", str(base)), ("@MUNGE_SOCKET@", str(sock)),
                       ("@SLURMCTLD_PORT@", str(_free_port())),
                       ("@SLURMD_PORT@", str(_free_port())), ("@CPUS@", str(os.cpu_count()))):
        template = template.replace(mark, value)
    assert not any("@" in line for line in template.splitlines() if not line.startswith("#"))
    conf.write_text(template)
    env = {**os.environ, "SLURM_CONF": str(conf)}
    procs: list[subprocess.Popen] = []
    try:
        procs.append(subprocess.Popen(
            ["runuser", "-u", "munge", "--", _which("munged"), "--foreground", "--force",
             f"--socket={sock}", f"--key-file={key}", f"--pid-file={mdir}/munged.pid",
             f"--log-file={mdir}/munged.log", f"--seed-file={mdir}/munged.seed"],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE))
        _wait(lambda: sock.exists() or procs[0].poll() is not None, 20, "munged",
              [mdir / "munged.log"])
        assert procs[0].poll() is None, procs[0].stderr.read()
        procs.append(subprocess.Popen([_which("slurmctld"), "-D", "-f", str(conf)], env=env,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        procs.append(subprocess.Popen([_which("slurmd"), "-D", "-f", str(conf)], env=env,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))

        def node_idle():
            r = subprocess.run(["sinfo", "-h", "-o", "%T"], env=env, capture_output=True,
                               text=True)
            return r.returncode == 0 and r.stdout.strip() == "idle"

        _wait(node_idle, 60, "the node to be idle",
              [base / "slurmctld.log", base / "slurmd.log"])
        yield env, base
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
        for p in reversed(procs):
            try:
                p.wait(20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
            if p.stderr:
                p.stderr.close()
        shutil.rmtree(base, ignore_errors=True)


SPEC = """
name = "slurm5"
base = "{inputs}/building5_friction.nml"
[zip]
slip_ratio = [0.0, 0.02, 0.05, 0.1, 0.2]
"friction.p" = {p}
"excitation.duration" = [6.0, 6.0, 6.0, 6.0, 6.0]
"""


def _spec(path: Path) -> Path:
    m = [300e3, 300e3, 300e3, 300e3, 250e3]
    w = [sum(m[i:]) * 9.80665 for i in range(5)]
    p = [[a * wi / 0.3 for wi in w] for a in (0.0, 0.02, 0.05, 0.1, 0.2)]
    path.write_text(SPEC.format(inputs=INPUTS, p=json.dumps(p)))
    return path


def _wait_job(env, job: str, timeout: float = 180):
    def gone():
        r = subprocess.run(["squeue", "-h", "-j", job], env=env, capture_output=True, text=True)
        return r.returncode != 0 or not r.stdout.strip()

    _wait(gone, timeout, f"job {job}")


def _job_id(stdout: str) -> str:
    line = next(x for x in stdout.splitlines() if x.startswith("submitted: job "))
    return line.split()[2]


def _same(a: Path, b: Path, n: int):
    for i in range(n):
        rid = f"r{i:04d}"
        assert (a / "runs" / f"{rid}.csv").read_bytes() == (b / "runs" / f"{rid}.csv").read_bytes()
        sa = json.loads((a / "runs" / f"{rid}.summary.json").read_text())
        sb = json.loads((b / "runs" / f"{rid}.summary.json").read_text())
        sa.pop("run_time_s")
        sb.pop("run_time_s")
        assert sa == sb


def test_job_array_gives_the_local_results(cluster, tmp_path):
    env, _ = cluster
    spec = _spec(tmp_path / "slurm5.toml")
    local, remote = tmp_path / "local", tmp_path / "remote"
    r = subprocess.run([*SWEEP, str(spec), "--out", str(local), "--quiet", "-j", "2"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr

    r = subprocess.run([*SWEEP, str(spec), "--out", str(remote), "--slurm", "--submit",
                        "--max-parallel", "2"], env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "#SBATCH --array=0-4%2" in (remote / "sweep.sbatch").read_text()
    _wait_job(env, _job_id(r.stdout))
    c = subprocess.run([*SWEEP, "collect", str(remote)], env=env, capture_output=True, text=True)
    assert c.returncode == 0, c.stdout + c.stderr
    assert "5 of 5 runs complete, 0 failed, 0 missing" in c.stdout
    _same(local, remote, 5)
    # the dampers work: the roof drift falls as the slip load rises
    drift = [json.loads((remote / "runs" / f"r{i:04d}.summary.json").read_text())["peak_s_m"][4]
             for i in range(5)]
    assert drift[0] > drift[2] > drift[4]

    # a lost run and a failed one: collect reports them and resubmits just those
    (remote / "runs" / "r0001.summary.json").unlink()
    (remote / "runs" / "r0001.csv").unlink()
    (remote / "runs" / "r0003.summary.json").unlink()
    (remote / "runs" / "r0003.error.txt").write_text("frictiondyn: error: simulated\n")
    c = subprocess.run([*SWEEP, "collect", str(remote)], env=env, capture_output=True, text=True)
    assert c.returncode == 1
    assert "3 of 5 runs complete, 1 failed, 1 missing" in c.stdout
    assert "failed: r0003 (index 3): frictiondyn: error: simulated" in c.stdout
    assert "missing: 1 (indices)" in c.stdout
    c = subprocess.run([*SWEEP, "collect", str(remote), "--resubmit", "--max-parallel", "2"],
                       env=env, capture_output=True, text=True)
    assert "#SBATCH --array=1,3%2" in (remote / "resubmit.sbatch").read_text()
    _wait_job(env, _job_id(c.stdout))
    c = subprocess.run([*SWEEP, "collect", str(remote)], env=env, capture_output=True, text=True)
    assert c.returncode == 0 and "5 of 5 runs complete" in c.stdout, c.stdout
    _same(local, remote, 5)
    rows = (remote / "results.csv").read_text().splitlines()
    assert len(rows) == 6 and all(",done," in x for x in rows[1:])


def test_a_job_array_in_a_folder_named_to_inject_commands(cluster, tmp_path):
    """A sweep directory whose name holds a quote, $(...), backticks, '#', '%' and blanks:
    sbatch reads the #SBATCH lines as written (the directory, the log file pattern), the
    tasks run every deck in that directory, and nothing the name asks for runs."""
    env, _ = cluster
    spec = tmp_path / "two.toml"
    spec.write_text(f'name = "two"\nbase = "{INPUTS}/building5_friction.nml"\n'
                    '[zip]\n"excitation.duration" = [2.0, 3.0]\n')
    out = tmp_path / "it's 100% a $(touch INJECTED_1) `touch INJECTED_2` # sweep"
    r = subprocess.run([*SWEEP, str(spec), "--out", str(out), "--slurm", "--submit"], env=env,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    job = _job_id(r.stdout)
    _wait_job(env, job)
    c = subprocess.run([*SWEEP, "collect", str(out)], env=env, capture_output=True, text=True)
    assert c.returncode == 0 and "2 of 2 runs complete" in c.stdout, c.stdout + c.stderr
    assert sorted(p.name for p in (out / "logs").glob("*.out")) == [f"{job}_0.out", f"{job}_1.out"]
    assert not list(tmp_path.rglob("INJECTED*"))
    assert not list(Path("/").glob("INJECTED*")) and not list(Path.home().glob("INJECTED*"))


def test_a_job_array_of_tolerance_runs_gives_the_local_results(cluster, tmp_path):
    """A sweep of two base decks, one with &integration tolerance: Slurm's tasks run the
    tolerance run by Python and the other by the executable; every summary equals the local
    sweep's (but the run time), the tolerance run's with its estimated errors."""
    from test_sweep_tolerance import BASE

    env, _ = cluster
    (tmp_path / "tol.nml").write_text(BASE.format(tolerance=", tolerance = 1e-3"))
    (tmp_path / "plain.nml").write_text(BASE.format(tolerance=""))
    spec = tmp_path / "tol.toml"
    spec.write_text('name = "tol"\n[cross]\ndeck = ["tol.nml", "plain.nml"]\n')
    local, remote = tmp_path / "local", tmp_path / "remote"
    r = subprocess.run([*SWEEP, str(spec), "--out", str(local), "--quiet"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    r = subprocess.run([*SWEEP, str(spec), "--out", str(remote), "--slurm", "--submit"], env=env,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert 'tolerance_runs=" 0 "' in (remote / "sweep.sbatch").read_text()
    _wait_job(env, _job_id(r.stdout))
    c = subprocess.run([*SWEEP, "collect", str(remote)], env=env, capture_output=True, text=True)
    assert c.returncode == 0 and "2 of 2 runs complete" in c.stdout, c.stdout + c.stderr
    for i in range(2):
        sa, sb = (json.loads((d / "runs" / f"r{i:04d}.summary.json").read_text()) for d in (local, remote))
        sa.pop("run_time_s")
        sb.pop("run_time_s")
        assert sa == sb
        assert ("estimated_error" in sb) == (i == 0)
