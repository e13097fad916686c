"""The caption drawn over a static meshcat page: what robot, at which q, and what each mark means.

meshcat's page has no place for text, so kinelab adds a small fixed box to the saved HTML (the live viewer
shows the scene only; ``kinelab view`` prints the same lines in the terminal).
"""

from __future__ import annotations

import html
from dataclasses import dataclass

STYLE = ("position:fixed;left:10px;top:10px;max-width:46%;padding:8px 12px;border-radius:6px;"
         "background:rgba(255,255,255,0.88);color:#1a1a1a;font:13px/1.45 system-ui,sans-serif;"
         "box-shadow:0 1px 4px rgba(0,0,0,0.3);z-index:10")


def tab_title(robot: str, view: str) -> str:
    """What a page's browser tab says: the robot and the view ("ur5 · branches — kinelab")."""
    return f"{robot} · {view} — kinelab"


def titled(page: str, title: str) -> str:
    """meshcat's page with its tab titled ``title`` (escaped) instead of "MeshCat"."""
    return page.replace("<title>MeshCat</title>", f"<title>{html.escape(title)}</title>", 1)


@dataclass(frozen=True)
class Table:
    """A table under the caption's lines: column names, rows of cells (text), the row to mark (or None)."""

    header: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    marked: int | None = None
    note: str = ""  # a line under the table (what its short column names stand for)


def caption_html(title: str, lines: list[str], table: Table | None = None) -> str:
    """The caption box: a bold title, one line per legend entry, then the table if any (text is escaped)."""
    body = "".join(f"<div>{html.escape(line)}</div>" for line in lines)
    return (f'<div id="kinelab-caption" style="{STYLE}"><b>{html.escape(title)}</b>{body}'
            f"{'' if table is None else table_html(table)}</div>")


def table_html(table: Table) -> str:
    """The table as HTML (id ``kinelab-table``), numbers right-aligned, the marked row bold on orange."""
    cell = "padding:1px 6px;text-align:right"
    head = "".join(f'<th style="{cell}">{html.escape(h)}</th>' for h in table.header)
    rows = []
    for k, row in enumerate(table.rows):
        mark = ' style="background:#fbd3b0;font-weight:bold"' if k == table.marked else ""
        rows.append(f"<tr{mark}>" + "".join(f'<td style="{cell}">{html.escape(c)}</td>' for c in row) + "</tr>")
    note = f'<div style="font-size:11px">{html.escape(table.note)}</div>' if table.note else ""
    return (f'<table id="kinelab-table" style="margin-top:6px;border-collapse:collapse;font-size:12px">'
            f"<tr>{head}</tr>{''.join(rows)}</table>{note}")


# a page with a table gives its caption a column of its own: over the scene it hid the copies behind it
SIDE_COLUMN = ("<style>#kinelab-caption{left:0!important;top:0!important;bottom:0;width:{w};"
               "max-width:none!important;box-sizing:border-box;overflow-y:auto;border-radius:0!important}"
               "#meshcat-pane{position:absolute;left:{w};right:0;top:0;bottom:0;"
               "width:auto!important;height:auto!important}</style>")


def with_caption(page: str, title: str, lines: list[str], table: Table | None = None) -> str:
    """The page with the caption box placed just before ``</body>`` (or at its end); with a table, the caption is
    a column on the left and the scene takes the rest of the width."""
    if table is not None:  # in the head: the viewer measures its pane when its script runs, before the body's end
        at = page.find("</head>")
        style = SIDE_COLUMN.replace("{w}", "36%")
        page = page[:at] + style + page[at:] if at >= 0 else style + page
    return before_body(page, caption_html(title, lines, table))


def before_body(page: str, box: str) -> str:
    """The page with the HTML ``box`` placed just before ``</body>`` (or at its end)."""
    at = page.rfind("</body>")
    return page[:at] + box + page[at:] if at >= 0 else page + box
