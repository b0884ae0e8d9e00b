"""Griffe extension for the API reference: reStructuredText roles in docstrings as code.

The package's docstrings name other objects the Sphinx way (``:class:`sim_core.SceneError```,
``:meth:`load```); in Markdown the role would show as literal text.  This extension rewrites
each role to a code span of its target before mkdocstrings renders the docstring, so the
source keeps one convention and the site shows ``sim_core.SceneError``.  Loaded by the
mkdocstrings handler (``extensions`` in mkdocs.yml).
"""

from __future__ import annotations

import re

import griffe

ROLE = re.compile(r":(?:py:)?(?:class|func|meth|attr|data|mod|exc|obj|const):`~?([^`]+)`")


class RstRoles(griffe.Extension):
    """Rewrite ``:role:`target``` to ```target``` in every loaded object's docstring."""

    def on_instance(self, *, obj, **kwargs) -> None:
        if obj.docstring is not None:
            obj.docstring.value = ROLE.sub(r"`\1`", obj.docstring.value)
