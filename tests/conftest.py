"""pytest configuration. Shared test helpers live in tests/helpers.py (import them from there)."""

# tests/fixtures holds input notebooks and scripts for the handouts and grading tests, not tests:
# keep `pytest --nbval-lax tests` from collecting them.
collect_ignore = ["fixtures"]
