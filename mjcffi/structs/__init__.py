"""Generated struct classes (issue 3)."""
