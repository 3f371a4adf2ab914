"""Text from files other people wrote (cell names, device names, result fields), escaped for where it lands.

Each medium has its own hazards: HTML runs script, a spreadsheet runs a CSV cell that starts with ``=``, a
Markdown table breaks on ``|`` and renders inline HTML, a terminal obeys escape sequences, and matplotlib reads
``$...$`` as mathematics (and fails on a lone ``$``). One function per medium, used wherever such text is
written.
"""

from __future__ import annotations

import html
import re

_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")


def for_terminal(text: str) -> str:
    """Control characters (escape sequences, bidirectional overrides, NUL) shown as ``\\x1b`` and the like."""
    return _CONTROL.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), str(text))


def for_html(text: str) -> str:
    """HTML text or attribute value."""
    return html.escape(str(text), quote=True)


def for_csv(text: str) -> str:
    """A CSV cell a spreadsheet will not run as a formula: a leading ``= + - @`` (or tab, carriage return) gets a
    quote in front, as spreadsheets expect (OWASP's CSV injection advice). Numbers written by us are not text
    and do not pass through here."""
    text = str(text)
    return "'" + text if text[:1] in ("=", "+", "-", "@", "\t", "\r") else text


def for_markdown(text: str) -> str:
    """A Markdown table cell: ``|`` escaped, line breaks as spaces, and ``< > &`` as HTML entities, so that
    the cell can neither end early nor carry HTML."""
    text = " ".join(str(text).splitlines())
    return html.escape(text, quote=False).replace("|", "\\|")


def for_plot(text: str) -> str:
    """Text for a matplotlib label or title: ``$`` escaped (mathtext), control characters shown as escapes."""
    return for_terminal(text).replace("$", r"\$")


# XML 1.0 allows no C0 control but tab, line feed and carriage return, no lone surrogate and neither U+FFFE nor
# U+FFFF (a parser refuses the whole file); C1 controls and bidirectional overrides are allowed but would mislead
# a reader of a CI page as they would a terminal.
_NOT_FOR_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069\ud800-\udfff\ufffe\uffff]")


def for_xml(text: str, *, attribute: bool = False) -> str:
    """XML text or (``attribute``) a double-quoted attribute value: ``& < > " '`` as entities (so ``]]>`` cannot
    end anything), characters XML does not allow or a reader should not obey shown as ``\\x01``-style escapes,
    and in an attribute tab and line breaks as character references (a parser would turn them into spaces)."""
    text = _NOT_FOR_XML.sub(lambda m: m.group().encode("unicode_escape", "backslashreplace").decode("ascii"), str(text))
    text = html.escape(text, quote=True)
    if attribute:
        text = text.replace("\t", "&#9;").replace("\n", "&#10;").replace("\r", "&#13;")
    return text


_UNSAFE_IN_FILE_NAME = re.compile(r"[^A-Za-z0-9._-]+")
MAX_SLUG = 80


def slug(text: str, fallback: str = "cell") -> str:
    """A file name made from a name someone else chose: letters, digits, ``. _ -`` only, no leading dot or dash,
    at most ``MAX_SLUG`` characters, so that it names a file in the working folder and never a path
    (``../../x`` -> ``x``, ``/etc/passwd`` -> ``etc-passwd``)."""
    s = _UNSAFE_IN_FILE_NAME.sub("-", str(text)).strip(".-")[:MAX_SLUG].strip(".-")
    return s or fallback
