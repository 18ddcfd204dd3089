"""The papers' experiments as exercises: starter code, a reference solution, automatic checks."""
