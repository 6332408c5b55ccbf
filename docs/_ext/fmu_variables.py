"""Sphinx directive ``fmu-variables``: the FMU's variable table, generated at build time from
``cushion_clutch.model.clutch_model.VARIABLES`` (name, causality, unit, description), with the start value
of every parameter and input and the allowed range the FMUs check. Nothing is copied by hand."""
from __future__ import annotations

from docutils import nodes
from sphinx.util.docutils import SphinxDirective


def _rows() -> list[tuple[str, str, str, str, str, str]]:
    from cushion_clutch.model.clutch_model import (OMEGA_SLIP_LIMIT, THETA_CM_LIMIT, VARIABLES, X_TO_LIMIT,
                                                   ClutchParameters, start_values)

    p = ClutchParameters()
    starts = start_values(p)
    inputs = {"x_to": f"|x_to| <= {X_TO_LIMIT:g}", "theta_cm": f"0 < theta_cm < {THETA_CM_LIMIT:g}",
              "omega_slip": f"|omega_slip| <= {OMEGA_SLIP_LIMIT:g}"}
    rows = []
    for name, causality, unit, description in VARIABLES:
        start, allowed = "", ""
        if causality in ("parameter", "input"):
            start = f"{starts[name]:g}"
        if causality == "parameter" and name in p.RANGES:
            lo, hi, lo_open, hi_open = p.RANGES[name]
            allowed = f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"
        if causality == "input":
            allowed = inputs.get(name, "")
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
