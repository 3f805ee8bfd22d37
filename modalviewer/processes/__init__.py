"""The viewer's child processes: a spectrum computation (``job_main``) and a mesh repair
(``repair_main``).  Nothing here imports the viewer or Qt, so a child starts with the
numerical core alone; a computation applies :func:`.core.memory.prepare_compute_process`."""
