"""cfmpa: an executable specification and checker for a dual-arm collision-free planner.

Layers point one way: ``spec`` <- ``impl`` <- ``proofs`` and ``runs`` <- ``report`` <- ``cli``;
``errors``, ``files``, ``gitstate`` and ``scenarios`` are leaves every layer may use
(docs/model.md §1).
"""

__version__ = "0.1.0"

__all__ = ["__version__"]
