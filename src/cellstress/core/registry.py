"""Plug-in registries through Python entry points, as pytest finds plug-ins and Gymnasium registers envs.

Five groups: ``cellstress.searchers``, ``cellstress.devices``, ``cellstress.criteria``,
``cellstress.simulators`` and ``cellstress.workers``. cellstress registers its own plug-ins the same way
(``pyproject.toml``), so a third party extends it with one module and one line in its own package metadata,
without editing cellstress::

    [project.entry-points."cellstress.searchers"]
    my-searcher = "my_package.my_module:MySearcher"

Each group is the one source of its names: the command line's choices and help, the campaign's defaults, the
report's colours and the cell schema's unions are all read from here. Names are listed in alphabetical order
(package metadata keeps no other). A name registered twice is an error, reported when the group is read,
because which of the two would run would otherwise depend on the order packages were installed.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from importlib.metadata import EntryPoint, entry_points

from cellstress.core.errors import PluginError

GROUPS = ("searchers", "devices", "criteria", "simulators", "workers")
SINGULAR = {"searchers": "searcher", "devices": "device", "criteria": "criterion", "simulators": "simulator",
            "workers": "worker model"}
OWN_DISTRIBUTION = "cellstress"


@dataclass(frozen=True)
class Plugin:
    """One registered plug-in: its name, the object it names (``module:attribute``) and who registered it."""

    group: str
    name: str
    value: str
    distribution: str


def _group(group: str) -> str:
    if group not in GROUPS:
        raise ValueError(f"unknown plug-in group {group!r} (groups: {', '.join(GROUPS)})")
    return f"cellstress.{group}"


def _distribution(ep: EntryPoint) -> str:
    dist = getattr(ep, "dist", None)
    return dist.metadata["Name"] if dist is not None else ""


@cache
def plugins(group: str) -> tuple[Plugin, ...]:
    """The plug-ins of ``group`` (see the module docstring for their order).

    Installed metadata is read once per process; a package installed later is seen by the next process."""
    found = [Plugin(group, ep.name, ep.value, _distribution(ep)) for ep in entry_points(group=_group(group))]
    if not any(p.distribution == OWN_DISTRIBUTION for p in found):
        raise PluginError(f"cellstress's own {group} are not registered: the package metadata is missing "
                          "(install cellstress with pip, e.g. pip install -e .)")
    seen: dict[str, Plugin] = {}
    for p in sorted(found, key=lambda p: (p.name, p.distribution != OWN_DISTRIBUTION, p.value)):
        first = seen.get(p.name)
        if first is not None and first.value != p.value:
            raise PluginError(f"the {SINGULAR[group]} name {p.name!r} is registered twice: by {first.distribution} "
                              f"({first.value}) and by {p.distribution or 'an unnamed package'} ({p.value})")
        seen.setdefault(p.name, p)
    return tuple(seen.values())


def names(group: str) -> tuple[str, ...]:
    """The registered names of ``group``, in registry order."""
    return tuple(p.name for p in plugins(group))


@cache
def load(group: str, name: str):
    """The object registered as ``name`` in ``group`` (a class, usually); PluginError naming the choices for an
    unknown name, or naming the plug-in when its module cannot be imported."""
    for p in plugins(group):
        if p.name == name:
            try:
                return EntryPoint(p.name, p.value, _group(group)).load()
            except (ImportError, AttributeError) as exc:
                raise PluginError(f"the {SINGULAR[group]} {name!r} ({p.value}, from {p.distribution}) cannot be "
                                  f"loaded: {exc}") from None
    raise PluginError(f"unknown {SINGULAR[group]} {name!r} (choose from {', '.join(names(group))})")


def load_all(group: str) -> dict[str, object]:
    """Every plug-in of ``group`` by name, in registry order (imports each one's module)."""
    return {n: load(group, n) for n in names(group)}
