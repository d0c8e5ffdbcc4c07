"""Rig files shipped with camdyn (TOML)."""
