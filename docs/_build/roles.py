"""A griffe extension: the docstrings' reST roles as Markdown code for mkdocstrings.

serialkin's docstrings cross-reference with Sphinx roles (``:func:`solve```,
``:class:`~serialkin.ik.IKResult```), which Markdown would show verbatim. Each role becomes
inline code with the name as a reader would write it (``~`` keeps the last component).
"""

from __future__ import annotations

import re

import griffe

_ROLE = re.compile(r":(?:py:)?(?:func|class|meth|mod|data|attr|exc|obj|const)`(~?)([^`]+)`")


def _code(match: re.Match[str]) -> str:
    tilde, name = match.groups()
    name = name.strip()
    if tilde:
        name = name.rsplit(".", 1)[-1]
    return f"`{name}`"


def plain_roles(text: str) -> str:
    """``text`` with every Sphinx role replaced by inline code."""
    return _ROLE.sub(_code, text)


class SphinxRoles(griffe.Extension):
    """Rewrite the roles of every docstring griffe loads."""

    def on_instance(self, *, obj: griffe.Object, **kwargs: object) -> None:  # noqa: D102
        if obj.docstring is not None:
            obj.docstring.value = plain_roles(obj.docstring.value)
