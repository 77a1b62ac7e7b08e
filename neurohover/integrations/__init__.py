"""Adapters to other libraries' interfaces (optional extras; each module imports its library)."""
