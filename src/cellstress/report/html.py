"""Self-contained HTML pages: images embedded as data URIs, styles and scripts inline (the 3D view,
``report/view3d``), no external URL, so a report can be mailed, archived or opened offline and shows the same
thing everywhere.
"""

from __future__ import annotations

import base64
from html import escape
from pathlib import Path

from cellstress.core.io import atomic_write_text

_MIME = {".png": "image/png", ".gif": "image/gif", ".mp4": "video/mp4"}

STYLE = """
body { font-family: system-ui, -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; margin: 2em auto;
       max-width: 1200px; padding: 0 1em; color: #222; line-height: 1.45; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; } h2 { font-size: 1.25em; margin-top: 1.6em;
     border-bottom: 1px solid #ddd; padding-bottom: 0.2em; }
.verdict { padding: 0.8em 1em; border-radius: 6px; font-size: 1.05em; margin: 1em 0; }
.hazard { background: #fde8e8; border-left: 6px solid #c62828; }
.safe { background: #e8f5e9; border-left: 6px solid #2e7d32; }
.warn { background: #fff8e1; border-left: 6px solid #f9a825; padding: 0.5em 1em; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f2f2f2; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
tr.unsafe td { background: #fde8e8; font-weight: bold; }
figure { margin: 1em 0; } figcaption { color: #555; font-size: 0.9em; }
img { max-width: 100%; height: auto; border: 1px solid #eee; }
code { background: #f4f4f4; padding: 0 0.2em; } footer { color: #777; font-size: 0.85em; margin-top: 3em; }
"""


def data_uri(path: str | Path) -> str:
    p = Path(path)
    mime = _MIME.get(p.suffix.lower(), "application/octet-stream")
    return f"data:{mime};base64,{base64.b64encode(p.read_bytes()).decode('ascii')}"


def figure(path: str | Path, caption: str, alt: str) -> str:
    return (f'<figure><img src="{data_uri(path)}" alt="{escape(alt)}"><figcaption>{escape(caption)}'
            f"</figcaption></figure>")


def table(header: list[str] | None, rows: list[list], numeric: set[int] | None = None,
          row_classes: list[str] | None = None) -> str:
    """An HTML table; ``numeric`` columns are right-aligned and never wrapped, ``header`` None has no head row."""
    numeric = numeric or set()
    out = ["<table>"]
    if header:
        out.append("<tr>" + "".join(f"<th>{escape(h)}</th>" for h in header) + "</tr>")
    for k, row in enumerate(rows):
        cls = f' class="{row_classes[k]}"' if row_classes and row_classes[k] else ""
        cells = "".join(f'<td class="num">{escape(str(v))}</td>' if i in numeric else f"<td>{escape(str(v))}</td>"
                        for i, v in enumerate(row))
        out.append(f"<tr{cls}>{cells}</tr>")
    out.append("</table>")
    return "\n".join(out)


def page(title: str, body: list[str], footer: str, extra_style: str = "") -> str:
    return "\n".join([
        "<!DOCTYPE html>",
        '<html lang="en">',
        "<head>",
        '<meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{escape(title)}</title>",
        f"<style>{STYLE}{extra_style}</style>",
        "</head>",
        "<body>",
        *body,
        f"<footer>{escape(footer)}</footer>",
        "</body>",
        "</html>",
        "",
    ])


def write_page(path: str | Path, text: str) -> Path:
    path = Path(path)
    atomic_write_text(path, text)
    return path
