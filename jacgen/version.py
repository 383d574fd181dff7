"""jacgen's version: one place that every stage can read without importing the package."""

__version__ = "0.1.0"
