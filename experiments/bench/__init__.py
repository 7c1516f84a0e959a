"""Speed figures (`playroom bench`)."""
