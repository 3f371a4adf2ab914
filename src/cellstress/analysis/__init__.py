"""Analyses of a cell beyond search: the static ISO 13855 / ISO 13857 check (``iso13855``) and the brute-force
probe behind a light curtain (``probe``)."""
