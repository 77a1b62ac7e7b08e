"""Gymnasium environments (registered on import)."""
