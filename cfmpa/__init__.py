"""cfmpa: an executable specification and checker for a dual-arm collision-free planner.

Layers point one way: ``spec`` <- ``impl``; ``proofs`` uses both; ``cli`` sits on top.
"""

__version__ = "0.1.0"

__all__ = ["__version__"]
