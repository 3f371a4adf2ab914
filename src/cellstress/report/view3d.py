"""The interactive 3D view inside a self-contained HTML page: plotly.js, the view's data and our script, all
inline, so the page opens from disk and asks no server for anything.

plotly.js comes from the ``plotly`` Python package (``plotly.offline.get_plotlyjs``, its bundled, minified
plotly.js), so ``pip install`` brings it and nothing is fetched at run time. Our part is ``view3d.js`` (the
scene from ``scene3d``'s data, the timeline, the view buttons) and the markup below. The same data gives the
same bytes: no random ids, no dates.
"""

from __future__ import annotations

from functools import lru_cache
from html import escape
from importlib import resources
from pathlib import Path

from cellstress.report import html as H
from cellstress.report.scene3d import ViewData

STYLE = """
.cs3d { border: 1px solid #ddd; border-radius: 6px; padding: 0.5em; margin: 1em 0; }
.cs3d-bar { display: flex; flex-wrap: wrap; gap: 0.5em; align-items: center; margin: 0.2em 0; }
.cs3d-bar input[type=range] { flex: 1 1 300px; }
.cs3d-bar button, .cs3d-bar select { font: inherit; padding: 0.1em 0.6em; }
#cs3d-info { font-variant-numeric: tabular-nums; font-size: 0.9em; white-space: pre-wrap; }
#cs3d-plot { width: 100%; height: 620px; }
.cs3d-hint { color: #666; font-size: 0.85em; }
.cs3d-legend { list-style: none; padding: 0; margin: 0.3em 0; display: flex; flex-wrap: wrap; gap: 0.2em 1.2em;
               font-size: 0.85em; }
.cs3d-legend li.active { font-weight: bold; }
.cs3d-legend .sw { display: inline-block; width: 0.9em; height: 0.9em; margin-right: 0.35em; vertical-align: -0.1em;
                   border: 1px solid #888; }
"""

SCRIPT_END = "</script"


@lru_cache(maxsize=1)
def plotly_js() -> str:
    """plotly.js as the installed ``plotly`` package bundles it (about 4.8 MB)."""
    import plotly.offline

    return _inline_script(plotly.offline.get_plotlyjs())


def plotly_version() -> str:
    import plotly.offline

    return str(plotly.offline.get_plotlyjs_version())


@lru_cache(maxsize=1)
def view_js() -> str:
    return _inline_script(resources.files("cellstress.report").joinpath("view3d.js").read_text(encoding="utf-8"))


def _inline_script(js: str) -> str:
    """Script text that cannot end its ``<script>`` element early."""
    if SCRIPT_END in js.lower():
        raise ValueError("script text holds '</script': it cannot be inlined")
    return js


def view_fragment(data: ViewData, episode_labels: bool = False) -> str:
    """The 3D view's markup and scripts, to place in a page's body (one per page: its ids are fixed)."""
    n_steps = max(ep["n"] for ep in data.episodes)
    pick = ""
    if episode_labels and len(data.episodes) > 1:
        options = "".join(f'<option value="{k}">{escape(ep["label"])}</option>' for k, ep in enumerate(data.episodes))
        pick = f'<label>witness <select id="cs3d-episode">{options}</select></label>'
    return "\n".join([
        '<div id="cs3d" class="cs3d" data-ready="0" data-step="0" data-marker="" data-active="">',
        f'<div class="cs3d-bar">{pick}<button type="button" id="cs3d-play">play</button>'
        f'<input type="range" id="cs3d-step" min="0" max="{n_steps - 1}" value="0" step="1" '
        'aria-label="simulation step"></div>',
        '<div class="cs3d-bar"><span id="cs3d-info"></span></div>',
        '<div class="cs3d-bar">view: <button type="button" data-view="iso">3D</button>'
        '<button type="button" data-view="top">top</button><button type="button" data-view="front">front</button>'
        '<button type="button" data-view="side">side</button><span class="cs3d-hint">drag to orbit, right-drag '
        "to pan, wheel to zoom</span></div>",
        '<div id="cs3d-plot"></div>',
        '<ul id="cs3d-legend" class="cs3d-legend"></ul>',
        "<noscript><p>The 3D view needs JavaScript (it runs from this file; nothing is fetched).</p></noscript>",
        "</div>",
        f"<script>{plotly_js()}</script>",
        f'<script type="application/json" id="cs3d-data">{data.to_json()}</script>',
        f"<script>{view_js()}</script>",
    ])


def view_page(path: str | Path, title: str, intro: list[str], data: ViewData, footer: str,
              episode_labels: bool = False) -> Path:
    """A page that is the 3D view (``cellstress show --3d``)."""
    body = [f"<h1>{escape(title)}</h1>", *intro, view_fragment(data, episode_labels)]
    return H.write_page(path, H.page(title, body, footer, extra_style=STYLE))
