"""MkDocs hooks for jaxcable's documentation (named in `mkdocs.yml`).

Docstrings may link to helpers in jaxcable's private modules (`jaxcable._advice.WaveFit`,
say). The reference documents public paths only, so those targets have no page: such a
link is shown as code, without a link, instead of failing the build. A link to a public
name that is not documented still fails `mkdocs build --strict`.
"""

import re

# An autoref whose target has a private part (`jaxcable._x.y`, `jaxcable.io._x.y`).
_PRIVATE = re.compile(r'<autoref (?![^>]*\boptional\b)([^>]*\bidentifier="(?:[\w.]*\.)?_[^"]*"[^>]*)>')


def on_page_content(html, page, config, files):
    """Mark links to private objects optional: mkdocs-autorefs links them if it can, and
    otherwise shows their text without a warning."""
    return _PRIVATE.sub(r"<autoref optional \1>", html)
