"""Safety criteria: which states are unsafe, and the reward that steers a search towards them."""

from cellstress.criteria.contact import ContactWhileMoving, criterion_for, with_criterion

__all__ = ["ContactWhileMoving", "criterion_for", "with_criterion"]
