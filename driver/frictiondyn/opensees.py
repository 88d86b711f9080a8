"""A structure built in OpenSeesPy, analysed by frictiondyn with friction dampers added.

Engineers build their frame in OpenSeesPy (nodes, elements, masses, supports), without its
friction elements. ``opensees_matrices`` assembles its stiffness K and mass M with the
``GimmeMCK`` integrator and ``printA`` (a full system of the model's equations);
``condense`` removes the DOFs without mass by static condensation; ``write_deck`` writes
K and M as Matrix Market files and a deck of ``&matrices`` with the dampers (``&braces``
between DOFs, or the table) and the rest of the analysis; ``frictiondyn.run`` runs it::

    import openseespy.opensees as ops
    from frictiondyn import opensees as fo
    ... build the frame with ops ...
    mats = fo.opensees_matrices(ops)
    deck = fo.write_deck("study", mats, direction=1,
                         braces=[fo.Brace((2, 1), None, slip_load=2e5, stiffness=4e8)],
                         excitation="&excitation\\n  excitation_type = 'record'\\n ... /")
    result = frictiondyn.run(deck)

OpenSeesPy is not a dependency of frictiondyn: this module imports nothing of it, and takes
the live ``openseespy.opensees`` module as an argument.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass
class StructureMatrices:
    """K and M of a structure over its equations, and the (node, dof) of each equation."""

    k: np.ndarray
    m: np.ndarray
    dofs: list[tuple[int, int]]   # (node tag, dof 1..ndf) of each equation, in order

    def index(self, node: int, dof: int) -> int:
        """The equation (0-based) of a node's DOF; KeyError when it has none (supported,
        constrained or condensed out)."""
        try:
            return self.dofs.index((node, dof))
        except ValueError:
            raise KeyError(f"node {node} DOF {dof} is not an equation of the structure (supported, "
                           "constrained, or without mass and condensed out)") from None


@dataclass
class Brace:
    """A friction damper in series with a brace (&braces) between two DOFs given as (node,
    dof) of the OpenSeesPy model, or between one and the table (``to`` None)."""

    at: tuple[int, int]
    to: tuple[int, int] | None
    slip_load: float
    stiffness: float
    label: str = ""


def opensees_matrices(ops) -> StructureMatrices:
    """K and M of the live OpenSeesPy model (its analysis objects are replaced and wiped
    afterwards; the model itself is left as it was): the ``GimmeMCK`` integrator gives
    A = m M + c C + k K, assembled in a full system and read by ``printA``. M is taken as
    (M + K) - K so that no step solves with a singular M."""
    def assemble(m: float, k: float) -> np.ndarray:
        ops.wipeAnalysis()
        ops.constraints("Transformation")
        ops.numberer("Plain")
        ops.system("FullGeneral")
        ops.algorithm("Linear")
        ops.integrator("GimmeMCK", m, 0.0, k)
        ops.analysis("Transient")
        ops.analyze(1, 0.0)
        n = ops.systemSize()
        return np.array(ops.printA("-ret"), dtype=float).reshape(n, n)

    k = assemble(0.0, 1.0)
    m = assemble(1.0, 1.0) - k
    n = k.shape[0]
    dofs: list[tuple[int, int] | None] = [None] * n
    for tag in ops.getNodeTags():   # the equations' numbers, before the analysis is wiped
        for d, eq in enumerate(ops.nodeDOFs(tag), start=1):
            if 0 <= eq < n:
                dofs[eq] = (tag, d)
    ops.wipeAnalysis()
    if any(x is None for x in dofs):
        raise ValueError("an equation of the OpenSeesPy model belongs to no node DOF")
    return StructureMatrices(0.5 * (k + k.T), 0.5 * (m + m.T), dofs)  # type: ignore[arg-type]


def condense(mats: StructureMatrices, tol: float = 0.0) -> StructureMatrices:
    """Static condensation of the DOFs without mass (M_ii <= tol max M_ii): K = K_tt -
    K_t0 K_00^-1 K_0t over the DOFs t with mass. M must be lumped (diagonal)."""
    m = mats.m
    if np.abs(m - np.diag(np.diag(m))).max() > 1e-12 * np.abs(m).max():
        raise ValueError("the OpenSeesPy model's mass matrix is not lumped (diagonal): give nodal masses")
    d = np.diag(m)
    keep = d > tol * d.max()
    k = mats.k
    kt = k[np.ix_(keep, keep)]
    if (~keep).any():
        k00 = k[np.ix_(~keep, ~keep)]
        kt = kt - k[np.ix_(keep, ~keep)] @ np.linalg.solve(k00, k[np.ix_(~keep, keep)])
    kt = 0.5 * (kt + kt.T)
    return StructureMatrices(kt, np.diag(d[keep]), [x for x, k_ in zip(mats.dofs, keep) if k_])


def _mtx(a: np.ndarray) -> str:
    n = a.shape[0]
    rows = [(i, j, float(a[i, j])) for j in range(n) for i in range(j, n) if a[i, j] != 0.0]
    return "\n".join(["%%MatrixMarket matrix coordinate real symmetric", f"{n} {n} {len(rows)}"]
                     + [f"{i + 1} {j + 1} {v!r}" for i, j, v in rows]) + "\n"


def write_deck(directory, mats: StructureMatrices, *, direction: int, braces: list[Brace],
               excitation: str, damping: str = "&damping\n  damping_type = 'none'\n/\n",
               integration: str = "", name: str = "structure", condensed: bool = False) -> Path:
    """Write ``<name>.nml``, ``<name>_K.mtx`` and ``<name>_M.mtx`` into ``directory``: the
    structure (condensed first unless ``condensed``), the table motion along OpenSees DOF
    ``direction`` (1 = x) of every node, the braces and the given groups (deck text of
    &excitation, &damping, &integration). Returns the deck's path."""
    if not condensed:
        mats = condense(mats)
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{name}_K.mtx").write_text(_mtx(mats.k))
    (out / f"{name}_M.mtx").write_text(_mtx(mats.m))
    labels = [f"node {n} dof {d}" for n, d in mats.dofs]
    influence = [1.0 if d == direction else 0.0 for _, d in mats.dofs]
    lines = ["&matrices", f"  k_file = '{name}_K.mtx'", f"  m_file = '{name}_M.mtx'",
             "  label = " + ", ".join(f"'{x}'" for x in labels),
             "  influence = " + ", ".join(repr(x) for x in influence), "/"]
    if braces:
        ni = [mats.index(*b.at) + 1 for b in braces]
        nj = [0 if b.to is None else mats.index(*b.to) + 1 for b in braces]
        lines += ["&braces", f"  n_braces = {len(braces)}", "  node_i = " + ", ".join(map(str, ni)),
                  "  node_j = " + ", ".join(map(str, nj)),
                  "  slip_load = " + ", ".join(repr(float(b.slip_load)) for b in braces),
                  "  stiffness = " + ", ".join(repr(float(b.stiffness)) for b in braces),
                  "  label = " + ", ".join(f"'{b.label or f'brace {i + 1}'}'" for i, b in enumerate(braces)),
                  "/"]
    deck = out / f"{name}.nml"
    deck.write_text("\n".join(lines) + "\n" + damping + excitation + integration)
    return deck
