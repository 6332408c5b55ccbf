"""Sphinx extension: the ``{cc}`` role writes a number computed at build time into the page.

    The closed torque is {cc}`closed_torque_Nm(20)` N·m at 20 °C.

The text is a call of a named function of :mod:`cushion_clutch.benchmarks.doc_numbers` (``NUMBERS``) with an
optional format (``{cc}`kiss_shift_mm(195):+.2f```); an unknown name or a failing call is a build error
(with ``-W``), so a page cannot quote a number that its code no longer computes.
"""
from __future__ import annotations

from docutils import nodes


def cc_role(name, rawtext, text, lineno, inliner, options=None, content=None):
    from cushion_clutch.benchmarks.doc_numbers import evaluate

    try:
        value = evaluate(text)
    except Exception as exc:                       # the page names a number the code cannot give: say where
        msg = inliner.reporter.error(f"{{cc}}`{text}`: {exc}", line=lineno)
        return [inliner.problematic(rawtext, rawtext, msg)], [msg]
    return [nodes.inline(rawtext, value, classes=["cc-number"])], []


def setup(app):
    app.add_role("cc", cc_role)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
