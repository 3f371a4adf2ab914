"""The version of cellstress (pinned in campaign manifests and result files)."""

__version__ = "0.3.0"
