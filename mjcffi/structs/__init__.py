"""Generated struct classes with lazy NumPy views; codegen writes them here."""
