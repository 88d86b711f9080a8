"""The wheel of tools/wheel.sh installs into a fresh virtual environment and runs a deck with
no compiler on the path, its extension and executable loading the libgfortran and LAPACK it
carries (not the system's). Builds the package once more (about 2-3 min); not under the
checked build, whose sanitizer runtime a fresh interpreter does not load."""

from __future__ import annotations

import os
import subprocess
import sys
import venv
from pathlib import Path

import pytest
from conftest import INPUTS

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.skipif(bool(os.environ.get("FRICTIONDYN_CHECKED")),
                                reason="the checked build runs the suite on its own build")


def _libs(binary: Path) -> dict[str, str]:
    out = subprocess.run(["ldd", str(binary)], capture_output=True, text=True, check=True).stdout
    libs = {}
    for line in out.splitlines():
        parts = line.split("=>")
        if len(parts) == 2:
            libs[parts[0].strip()] = parts[1].split("(")[0].strip()
    return libs


def test_wheel_installs_and_runs_without_a_compiler(tmp_path):
    r = subprocess.run(["bash", str(ROOT / "tools" / "wheel.sh"), str(tmp_path / "wh")],
                       capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr[-3000:]
    wheels = list((tmp_path / "wh").glob("frictiondyn-*-manylinux_*.whl"))
    assert len(wheels) == 1, r.stdout
    env_dir = tmp_path / "env"
    venv.EnvBuilder(with_pip=True).create(env_dir)
    py = env_dir / "bin" / "python"
    r = subprocess.run([str(py), "-m", "pip", "install", "-q", str(wheels[0])],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-3000:]
    # no compiler on the path: the environment's own bin alone
    clean = {"PATH": str(env_dir / "bin"), "HOME": str(tmp_path)}
    for tool in ("gfortran", "gcc", "cc"):
        assert subprocess.run(["/bin/sh", "-c", f"command -v {tool}"], env=clean).returncode != 0
    work = tmp_path / "work"
    work.mkdir()
    (work / "test4_velocity.nml").write_text((INPUTS / "test4_velocity.nml").read_text())
    r = subprocess.run([str(py), "-m", "frictiondyn", "run", "test4_velocity.nml"], cwd=work,
                       env=clean, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    # the wheel's executable, on the path of the environment alone, matches the reference
    # outputs by the rules every build is judged by (tests/reference_check.py)
    exe_path = subprocess.run(["/bin/sh", "-c", "command -v frictiondyn"], env=clean,
                              capture_output=True, text=True).stdout.strip()
    assert exe_path.startswith(str(env_dir)), exe_path
    r = subprocess.run([sys.executable, str(ROOT / "tests" / "reference_check.py"), exe_path,
                        str(INPUTS / "test4_velocity.nml")], capture_output=True, text=True,
                       env={**os.environ, "PATH": clean["PATH"]})
    assert r.returncode == 0, r.stdout + r.stderr
    # the extension and the executable load the libraries the wheel carries
    site = next((env_dir / "lib").glob("python3*/site-packages"))
    ext = next((site / "frictiondyn").glob("_core*.so"))
    exe = next((site / "frictiondyn.scripts").glob("frictiondyn"))
    for binary in (ext, exe):
        libs = _libs(binary)
        for name in ("libgfortran", "liblapack"):
            found = [path for lib, path in libs.items() if lib.startswith(name)]
            assert found and all("frictiondyn.libs" in p for p in found), (binary, libs)
