"""Transitional alias of :mod:`feederkit.mechanics.polygon_classes` (the Fig. 14 classes)."""

from feederkit.mechanics.polygon_classes import CLASS_NAMES, PolygonClass, polygon_class

__all__ = ["CLASS_NAMES", "PolygonClass", "polygon_class"]
