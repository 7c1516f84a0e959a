"""Measuring trials: the project's evaluation and the study's tests, in rooms."""
