"""Real acquisition: Pico firmware, regulator driver, cameras, resumable ramp sessions, emulator.

Layout (one job per module):

- ``firmware/``: MicroPython firmware (``main.py``) and its pure logic (``rigcore.py``), which the
  host imports too (tests, emulator) so the device and the emulator run the same code.
- ``protocol.py``: host-side encoding of commands and parsing of replies.
- ``driver.py``: pyserial driver with host-side limits and calibration.
- ``calibration.py``: kPa <-> DAC-code calibration (two-point or multi-point) and its file.
- ``emulator.py``: the Pico over a pseudo-terminal, with fault injection.
- ``cameras.py``: camera backends (OpenCV, shell command, watched folder, synthetic).
- ``session.py``: the ramp plan and what is already recorded (resume).
- ``acquire.py``: runs a plan on a rig, writing the photo set atomically, venting on any stop.
- ``acquire_cli.py`` / ``cli.py``: the ``acquire`` and ``rig`` subcommands.
"""
