"""Reading results: a batch's tables, statistics, the study's maps (no MuJoCo)."""
