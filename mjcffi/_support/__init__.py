"""The support layer: what the generated code and the public modules stand on.

Loading the compiled module (library), MuJoCo's errors as exceptions (errors) and
the run-time error contract every call keeps (contract), zero-copy views (views),
argument marshalling and prepared calls (marshal, prepared), model loading and
checks (loading, modelcheck/), named access (named), what the mjr_* functions
check (mjr), the spec element helpers (elements, element_*, handles, checks),
plugins, callbacks, and small tools.  Private: nothing here is a public path.
Imports only the compiled module, the generated tables (mjcffi/_generated/) and
itself.
"""
