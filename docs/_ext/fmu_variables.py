"""Sphinx directive ``fmu-variables``: the FMU's variable table, generated at build time from
``cushion_clutch.model.clutch_model.VARIABLES`` (name, causality, unit, description), with the start value
of every parameter and input and the allowed range the FMUs declare and check (``clutch_model.declared_ranges``,
the one range table). Nothing is copied by hand."""
from __future__ import annotations

from docutils import nodes
from sphinx.util.docutils import SphinxDirective


def _number(v: float) -> str:
    """A bound as short as it reads exactly (``:g`` where that is the same number, else repr)."""
    return f"{v:g}" if float(f"{v:g}") == v else repr(float(v))


def allowed_text(rng: tuple) -> str:
    """The "allowed" cell of a range (low, high, low open, high open): ``[lo, hi]``, ``(`` / ``)`` at an open end."""
    lo, hi, lo_open, hi_open = rng
    return f"{'(' if lo_open else '['}{_number(lo)}, {_number(hi)}{')' if hi_open else ']'}"


def _rows() -> list[tuple[str, str, str, str, str, str]]:
    """(name, causality, unit, start, allowed, meaning) of every variable; allowed from the FMU's one range table
    (``clutch_model.declared_ranges`` with the default tables, as the default FMU declares and checks them)."""
    from cushion_clutch.model import load_table
    from cushion_clutch.model.clutch_model import VARIABLES, ClutchParameters, declared_ranges, start_values

    starts = start_values(ClutchParameters())
    ranges = declared_ranges(load_table())
    rows = []
    for name, causality, unit, description in VARIABLES:
        start = f"{starts[name]:g}" if causality in ("parameter", "input") else ""
        allowed = allowed_text(ranges[name]) if name in ranges else ""
        if name == "facing_wear":
            description += "; the maximum is the default cover's wear limit with the default tables"
        rows.append((name, causality, unit, start, allowed, description))
    return rows


class FmuVariables(SphinxDirective):
    """``.. fmu-variables::``: a table of every FMU variable in value-reference order."""

    has_content = False

    def run(self):
        header = ("name", "causality", "unit", "start", "allowed", "meaning")
        widths = (18, 9, 6, 8, 14, 45)
        table = nodes.table()
        group = nodes.tgroup(cols=len(header))
        table += group
        for w in widths:
            group += nodes.colspec(colwidth=w)

        def row(cells, literal_first=True):
            r = nodes.row()
            for i, c in enumerate(cells):
                entry = nodes.entry()
                entry += nodes.paragraph("", "", nodes.literal(c, c) if (i == 0 and literal_first) else nodes.Text(c))
                r += entry
            return r

        head = nodes.thead()
        head += row(header, literal_first=False)
        group += head
        body = nodes.tbody()
        for cells in _rows():
            body += row(cells)
        group += body
        return [table]


def setup(app):
    app.add_directive("fmu-variables", FmuVariables)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
