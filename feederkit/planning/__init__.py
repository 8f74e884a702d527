"""Planners on the abstract push-align machine (sections 4, 6, 8.5): no geometry here."""
