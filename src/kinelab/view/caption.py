"""The caption drawn over a static meshcat page: what robot, at which q, and what each mark means.

meshcat's page has no place for text, so kinelab adds a small fixed box to the saved HTML (the live viewer
shows the scene only; ``kinelab view`` prints the same lines in the terminal).
"""

from __future__ import annotations

import html

STYLE = ("position:fixed;left:10px;top:10px;max-width:46%;padding:8px 12px;border-radius:6px;"
         "background:rgba(255,255,255,0.88);color:#1a1a1a;font:13px/1.45 system-ui,sans-serif;"
         "box-shadow:0 1px 4px rgba(0,0,0,0.3);z-index:10")


def caption_html(title: str, lines: list[str]) -> str:
    """The caption box: a bold title, then one line per legend entry (text is escaped)."""
    body = "".join(f"<div>{html.escape(line)}</div>" for line in lines)
    return f'<div id="kinelab-caption" style="{STYLE}"><b>{html.escape(title)}</b>{body}</div>'


def with_caption(page: str, title: str, lines: list[str]) -> str:
    """The page with the caption box placed just before ``</body>`` (or at its end)."""
    return before_body(page, caption_html(title, lines))


def before_body(page: str, box: str) -> str:
    """The page with the HTML ``box`` placed just before ``</body>`` (or at its end)."""
    at = page.rfind("</body>")
    return page[:at] + box + page[at:] if at >= 0 else page + box
