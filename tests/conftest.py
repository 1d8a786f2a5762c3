"""Shared test set-up: tests/ is on sys.path, so test modules can `import factory`."""
