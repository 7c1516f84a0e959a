"""The numbers a batch runs its workers by, in a module of their own so that the command line
shows them as defaults without importing Dask or the project's computing parts."""

# How long a batch waits for a first worker before it gives up (s; `--worker-wait`): a
# scheduler whose workers are queued jobs may need minutes.
WORKER_WAIT_S = 600
# How long a running batch may have no worker before it says so, once (s).
NO_WORKER_NOTICE_S = 60
# How often a running batch counts its workers (s).
WORKER_COUNT_EVERY_S = 5
# How many times a trial is run again after its worker dies, or after a fault that may pass
# (a full disk freed, a file system back) (`--retries`): Dask's own default allowed failures.
RETRIES = 3
