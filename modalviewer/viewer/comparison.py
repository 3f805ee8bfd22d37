"""Side-by-side comparison of two or three operators (the paper's Fig. 1) or distance
kinds (Figs. 6, 7) on the loaded mesh (no Qt, no VTK).  A :class:`Comparison` reads the
viewer's state and never changes it; :meth:`Comparison.views` gives each view's field.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from psygnal import Signal

from ..core.operators import DISTANCE_KINDS, OPERATOR_INFO, operator_for_distance
from .derived import Field
from .state import ViewerState
from .wording import approximation_mark


def item_label(item: str) -> str:
    """A comparison item (an operator or a distance kind) in a few words."""
    return DISTANCE_KINDS[item] if item in DISTANCE_KINDS else OPERATOR_INFO[item].short_label


@dataclass
class ComparisonView:
    """One view: ``field`` (None: the plain surface, ``title`` says why) and ``marker``."""

    item: str
    title: str
    field: Field | None = None
    marker: int | None = None


class Comparison:
    """Two or three ``items``, all operators or all distance kinds: operator views show
    one mode index, distance views the threshold map marking the main display's share.
    ``changed`` is emitted when the mode index changes."""

    changed = Signal()

    def __init__(self, state: ViewerState, items: list[str]):
        items = list(items)
        if not 2 <= len(items) <= 3:
            raise ValueError("compare two or three operators or distance kinds")
        distances = [item in DISTANCE_KINDS for item in items]
        unknown = [i for i in items if i not in DISTANCE_KINDS and i not in OPERATOR_INFO]
        if unknown:
            raise ValueError(
                f"unknown comparison item {unknown[0]!r}: operators "
                f"{', '.join(OPERATOR_INFO)} or distances {', '.join(DISTANCE_KINDS)}"
            )
        if any(distances) and not all(distances):
            raise ValueError("compare operators with operators, or distances with distances")
        self.state = state
        self.items = items
        self.distances = all(distances)
        self._mode_index: int | None = 0 if self.distances else None

    @property
    def mode_index(self) -> int:
        """The operator views' mode index: the first operator's first non-zero mode until
        changed."""
        if self._mode_index is None:
            if self.state.spectrum(self.items[0]) is None:
                return 0
            self._mode_index = self.state.first_nonzero_mode(self.items[0])
        return self._mode_index

    @property
    def title(self) -> str:
        return "compare " + " / ".join(item_label(i) for i in self.items)

    def show_mode(self, index: int) -> None:
        """Mode ``index`` of each operator (clipped to each spectrum's modes)."""
        self._mode_index = max(0, int(index))
        self.changed.emit()

    def step(self, step: int) -> None:
        if not self.distances:
            self.show_mode(self.mode_index + step)

    def views(self) -> list[ComparisonView]:
        """What each view shows now."""
        if self.distances:
            return self._distance_views()
        return [self._mode_view(item) for item in self.items]

    def _mode_view(self, item: str) -> ComparisonView:
        spec = self.state.spectrum(item)
        if spec is None:
            return ComparisonView(item, f"{item_label(item)}: no spectrum")
        j = int(np.clip(self.mode_index, 0, spec.k - 1))
        scalar, disp = self.state.derived.mode_fields(spec, j)
        field = Field(
            values=scalar,
            colormap="diverging",
            isolines=self.state.style.isolines,
            displacement=disp,
            title=f"{item_label(item)} mode {j}",
        )
        lam = "0 (zero mode)" if spec.zero_mode_mask()[j] else f"{spec.eigenvalues[j]:.5g}"
        mark = approximation_mark(spec, self.state.is_coarse(item))
        return ComparisonView(item, f"{item_label(item)}{mark}: mode {j}, lambda = {lam}", field)

    def _distance_views(self) -> list[ComparisonView]:
        state, derived = self.state, self.state.derived
        vertex = state.picked
        shown = state.picked_file_vertex  # the titles give the file's number
        display = state.display
        # every kind marks the share of the surface the main display's map marks
        # (without one, the share its threshold maps keep)
        share = derived.marked_share()
        if share is None and display.keep_share:
            share = display.threshold_share
        views = []
        for item in self.items:
            d = derived.distance_map(item) if vertex is not None else None
            if d is None:
                need = (
                    "pick a vertex in the main window"
                    if vertex is None
                    else "its spectrum is not computed yet"
                )
                views.append(ComparisonView(item, f"{item_label(item)}: {need}", marker=vertex))
                continue
            op = operator_for_distance(item)
            mark = approximation_mark(state.spectrum(op), state.is_coarse(op))
            title = f"{item_label(item)}{mark} from vertex {shown}"
            if display.distance_display == "threshold":
                fraction = (
                    display.threshold if share is None else derived.threshold_for_share(share, d)
                )
                thr = fraction * float(d.max())
                similar = derived.surface_share(d, thr)
                field = Field(d, "threshold", title=item_label(item), threshold=thr)
                field.share_similar = similar
                title += f": blue < {thr:.3g} ({100.0 * similar:.1f} %)"
            else:
                field = derived.scaled(Field(d, "sequential", title=item_label(item)))
            views.append(ComparisonView(item, title, field, vertex))
        return views
