"""The one list of operators modalviewer computes spectra of, and what each one is.

Every other module (pipeline, viewer, CLI, plots) asks this registry for an operator's
label, the number of unknowns per vertex, the distance it defines and its cost, instead
of keeping its own list.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    "OperatorInfo",
    "OPERATOR_INFO",
    "OPERATOR_NAMES",
    "DISTANCE_KINDS",
    "operator_info",
    "operator_for_distance",
]


@dataclass(frozen=True)
class OperatorInfo:
    """What the viewer and the library need to know about one operator.

    name : key used in files, the API and the cache.
    label : words for menus, legends and titles.
    short_label : a few words for narrow places (comparison titles, plot legends).
    unknowns_per_vertex : 3 for displacement fields, 1 for scalar fields.
    distance_kind : the multi-scale distance this operator's spectrum defines, or None.
    nonzeros_per_row : typical non-zeros per row of K (for memory and time estimates).
    has_weights : whether the bending and membrane weights apply.
    """

    name: str
    label: str
    short_label: str
    unknowns_per_vertex: int
    distance_kind: str | None
    nonzeros_per_row: int
    has_weights: bool

    def unknowns(self, n_vertices: int) -> int:
        return self.unknowns_per_vertex * int(n_vertices)

    def nonzeros(self, n_vertices: int) -> int:
        return self.unknowns(n_vertices) * self.nonzeros_per_row


OPERATOR_INFO: dict[str, OperatorInfo] = {
    info.name: info
    for info in (
        OperatorInfo("laplacian", "Laplacian (cotan)", "Laplacian", 1, "hks", 7, False),
        OperatorInfo(
            "modified_dirichlet",
            "Modified Dirichlet energy E_D^N",
            "E_D^N",
            1,
            "feature",
            7,
            False,
        ),
        OperatorInfo(
            "shells", "Discrete Shells (3D vibrations)", "Shells 3D", 3, "vibration", 42, True
        ),
        OperatorInfo(
            "shells_normal",
            "Discrete Shells, normal variations",
            "Shells normal",
            1,
            None,
            19,
            True,
        ),
    )
}
OPERATOR_NAMES: tuple[str, ...] = tuple(OPERATOR_INFO)

DISTANCE_KINDS: dict[str, str] = {
    "vibration": "Vibration distance",
    "feature": "Feature distance",
    "hks": "Heat kernel distance",
}
"""Distance kinds (paper Section 6) and their names in words."""


def operator_info(name: str) -> OperatorInfo:
    """The registry entry of ``name``; a ValueError naming the known operators otherwise."""
    try:
        return OPERATOR_INFO[name]
    except KeyError:
        raise ValueError(
            f"unknown operator {name!r}; choose one of {', '.join(OPERATOR_NAMES)}"
        ) from None


def operator_for_distance(kind: str) -> str:
    """The operator whose spectrum defines distance ``kind`` (vibration -> shells, ...)."""
    for info in OPERATOR_INFO.values():
        if info.distance_kind == kind:
            return info.name
    raise ValueError(f"unknown distance kind {kind!r}; choose one of {', '.join(DISTANCE_KINDS)}")
