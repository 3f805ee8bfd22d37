"""Plumbing of the processes that exist to compute: the viewer's child process
(``python -m modalviewer.processes.job_main``) and the memory settings, which the
command line and the benchmarks apply too.  Nothing here imports the viewer or Qt, so a
child starts with the numerical core alone."""
