"""A deck read into an f90nml Namelist, for the tools that write decks from it (sweep,
converge): the library reads it first, and the Namelist must say what the library read."""

from __future__ import annotations

import io
import warnings
from pathlib import Path

import f90nml

from ._api import DeckError, FrictiondynError, Session


def read_namelist(text: str, path: Path) -> f90nml.Namelist:
    """The deck ``text`` (from ``path``) as a Namelist whose lists are arrays from element 1.

    - The library reads it first: its checks, and its messages with the deck's own lines.
    - f90nml's warnings are errors: it drops values it cannot place (a section with a
      negative stride, ``u0(2:1:-1) = ...``), which would change the model silently.
    - A 1-D array given from an element above 1 (``u0(2) = 0.002``, ``height(2:4) = ...``)
      becomes a list from element 1 with empty places before (nulls: those elements keep
      their defaults), so that element i of the list is element i of the array; f90nml
      keeps the start apart from the values, and a copy of the values alone moved them to
      element 1. Arrays of two dimensions keep their start (``mu_table_v(:, 2)``).
    """
    with Session.from_text(text, path.name, path.parent):
        pass
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            nml = f90nml.reads(text)
        except Exception as exc:  # f90nml raises several kinds, and its warnings
            raise DeckError(
                f"{path}: the deck runs alone, but f90nml, which writes the decks of sweeps "
                f"and convergence studies from it, cannot read it as the library does "
                f"({type(exc).__name__}: {exc}); write that assignment more plainly"
            ) from None
    for group in nml.values():
        for var, start in list(group.start_index.items()):
            if len(start) != 1 or start[0] is None:
                continue
            values = group[var] if isinstance(group[var], list) else [group[var]]
            group[var] = [None] * (start[0] - 1) + list(values)
            del group.start_index[var]
    # the deck as f90nml writes it again must be one the library reads (a ';' between values,
    # a 'q' exponent, a logical written 'Frog' are read by gfortran but not by f90nml)
    written = write_namelist(nml)
    try:
        with Session.from_text(written, path.name, path.parent):
            pass
    except FrictiondynError as exc:
        raise DeckError(
            f"{path}: the deck runs alone, but f90nml, which writes the decks of sweeps and "
            f"convergence studies from it, reads it otherwise: written again it gives "
            f"\"{exc}\"; write the values that message names more plainly"
        ) from None
    return nml


def write_namelist(nml: f90nml.Namelist) -> str:
    """The namelist as deck text."""
    buf = io.StringIO()
    nml.write(buf)
    return buf.getvalue()


def copy_namelist(nml: f90nml.Namelist) -> f90nml.Namelist:
    """A copy whose groups and lists can be changed without changing ``nml``."""
    out = f90nml.Namelist()
    for name, variables in nml.items():
        g = f90nml.Namelist()
        for k, v in variables.items():
            g[k] = [list(x) if isinstance(x, list) else x for x in v] if isinstance(v, list) else v
        g.start_index.update({k: list(s) for k, s in variables.start_index.items()})
        out[name] = g
    return out
