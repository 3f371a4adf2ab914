"""The lowest layer: typed records, the plug-in protocols, the registries, errors and file input/output.

Everything else in cellstress builds on these; nothing here imports another cellstress package.
"""
