"""The frirom input deck: one TOML file, parsed into settings, then built (docs/deck.md).

A deck names the structure either as assembled matrices used as they are (``[model]``,
MatrixMarket, DoFs by index or label) or as FE matrices to reduce (``[fe_model]`` with
``[reduction]``: Craig-Bampton, GSI or multi-stage interface modes, cached), then the
damping, excitation, contacts, harmonics, frequency range, continuation options and
outputs. With ``[fe_model]``, contacts join node sets (pairs matched by coordinates, local
frame from a normal), and excitation and outputs name FE nodes and directions
(``"ACTIVE:z"``, ``"1234:UX"``): the reduced coordinates never appear in a deck.
``[reduction.cyclic]`` makes the reduced model one sector of a tuned rotor under an
engine-order travelling wave: ``Deck.model()`` is then a :class:`frirom.model.CyclicModel`
whose modes (one Hermitian eigen-solve per nodal diameter the harmonics live on) are
computed after the cached reduction.

Two steps, two layers:

- :mod:`frirom.deck.schema` (with :mod:`~frirom.deck.schema_model`,
  :mod:`~frirom.deck.schema_contacts` and the typed readers of :mod:`~frirom.deck.fields`):
  :func:`parse_deck` checks every field and returns plain settings objects
  (:class:`~frirom.deck.schema.DeckSettings`); no matrix is read, nothing is reduced.
- :mod:`frirom.deck.build` (with :mod:`~frirom.deck.build_cyclic`): :func:`build_deck`
  reads the matrices (or builds or reuses the reduced model), resolves the DoFs and
  returns a :class:`Deck` holding plain numpy/scipy data; ``Deck.model()``,
  ``Deck.excitation()`` and ``Deck.options()`` build the solver's objects from it.

``load_deck(path)`` does both. Every malformed field raises :class:`frirom.InputError`
naming the deck file, the TOML key path (``contacts[2].mu``) and what was expected.
"""

from __future__ import annotations

from ..reduction.cyclic import engine_order_loads
from .build import ContactSpec, Deck, build_deck, read_matrix
from .schema import DeckSettings, parse_deck
from .schema_model import MATRIX_FORMATS

__all__ = ["Deck", "ContactSpec", "DeckSettings", "load_deck", "parse_deck", "build_deck",
           "engine_order_loads", "read_matrix", "MATRIX_FORMATS"]


def load_deck(path, allow_code=()) -> Deck:
    """Read, check and build a deck file; raises :class:`frirom.InputError` on any bad
    field. ``allow_code``: modules a contact law ``"module:function"`` may import
    (the CLI's ``--allow-code``; :func:`frirom.laws.load_law`)."""
    return build_deck(parse_deck(path, allow_code=allow_code))
