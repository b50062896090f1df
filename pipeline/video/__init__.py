"""Video photo sets: a video file plus its pressure log, measured frame by frame.

A video photo set is a photo set (DESIGN.md) whose ``manifest.csv`` has one row per *video*
instead of one per image: ``video, pressure_log, material, actuator, trial`` and optionally
``clock_offset_s`` and ``frame_times`` (plus any settings column, as for photos).  Measuring
streams every frame through the same per-row :class:`~pipeline.measure.settings.MeasureSettings`
and the same process pool as photos; ``angles.csv`` gets one row per frame with ``frame`` and
``time_s`` (on the pressure log's clock).

Modules (each imports only what its job needs; the worker side imports no pandas):

``reader``      open / probe a video with OpenCV and stream its frames (MJPEG packets or frames)
``timeline``    the pressure log: reading, spans, per-frame pressure, direction and steps
``worker``      the pool task: measure a chunk of consecutive frames
``measure``     a video photo set -> angles.csv rows (chunks, pressure per frame, failed rows)
``continuous``  continuous aggregation: binned loops, settling curves, step-response figures
``pages``       the report page of a video dataset
"""
