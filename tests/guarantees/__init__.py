"""The end-to-end promises of the reliability page, each checked by a run as a user makes it
(the library's ``run``, or ``crosscheck`` itself in a subprocess) and judged on the rows it
leaves behind.

Bad input is refused before any work:

- a bad command line of ``run``, ``run --resume`` or ``new-case`` is an exit 2 naming the
  option and what it allows, before any folder is made: ``test_refused_before_work.py``
  (malformed case files are the loader's: ``tests/cases/test_malformed.py``,
  ``tests/cases/test_load.py``).

A crashing, hanging or leaking engine costs one case x engine, never the run:

- real faults of today's engines (FCL's hang and segfault, pymunk's abort) and the whole
  bad-input suite through every engine: ``test_engine_faults.py`` (the worker mechanism
  with fakes that hang, abort and segfault: ``tests/run/test_isolation.py``; a worker over
  ``--worker-memory`` recycled, a case over it alone a ``crash``:
  ``tests/run/test_worker_limits.py``);
- with ``--no-isolation``, a declared hang is never run and Ctrl-C stops between cases:
  ``test_inprocess_hangs.py``.

Nothing computed is lost:

- SIGKILL at random moments and ``--resume``, a half-written last line, ``--jobs 1`` against
  ``--jobs 2``, a new run refusing a folder with results: ``test_resume.py``;
- a run killed at any moment, even before ``run.json`` exists: ``test_early_kill.py``;
- a full disk: ``test_full_disk.py``;
- a Dask worker or the scheduler lost mid-run: ``test_dask_faults.py``;
- Ctrl-C of an isolated run: ``test_ctrl_c.py``;
- a report that fails to render: ``test_report_failure.py``;
- a second run into a folder in use is refused (a lock): ``test_one_run_per_folder.py``;
- 100,000 cases in flat resident memory: ``test_flat_memory.py``;
- the repeat check interrupted and resumed, each pair asked again once:
  ``test_repeat_check_resume.py`` (what it flags: ``tests/run/test_repeat_check.py``).

(A fuzz campaign killed and resumed: ``tests/studies/test_fuzz_campaign.py``.)
"""
