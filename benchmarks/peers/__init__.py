"""Helpers that run peer tools in their own virtual environments (never imported by hwpts)."""
