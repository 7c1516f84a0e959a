"""Batches of trials on Dask: their specs, the scheduler, profiles and ablations."""
