"""Contact of the sheet with the rigid tools of deep drawing: the analytic tools (tools.py)."""
