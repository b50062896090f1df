"""Firmware for the Raspberry Pi Pico (MicroPython).

Copy ``rigcore.py`` and ``main.py`` to the Pico's file system (e.g. ``mpremote cp rigcore.py :``
and ``mpremote cp main.py :``).  ``rigcore`` is pure Python with no MicroPython-only imports, so
the host imports it for tests and for the emulator (:mod:`pipeline.rig.emulator`).
"""
from pathlib import Path

#: folder holding the files to copy to the Pico
FIRMWARE_DIR = Path(__file__).parent
