"""MicroPython firmware for the Raspberry Pi Pico of the actuator rig (paper Section II.C).

Wiring (change the pin numbers below to match your board):

- MCP4921 12-bit DAC on SPI0: SCK GP18, MOSI (SDI) GP19, CS GP17 (LDAC tied low); its output,
  through an op-amp of gain 5/3.3, drives the 0-5 V command input of the SMC ITV1031 regulator.
- Regulator monitor output (1-5 V) through a 0.6 divider to ADC0 (GP26).
- Emergency-stop button (normally open, to GND) on GP15 with the internal pull-up.
- HX711 load-cell amplifier (blocked force): DOUT GP4, PD_SCK GP5 (channel A, gain 128).

The protocol and every computation live in ``rigcore.py`` (copied next to this file), which the
host tests and emulates; this file only binds it to the pins and the USB serial port.
Install: ``mpremote cp rigcore.py : && mpremote cp main.py : && mpremote reset``.
"""

import select
import sys
import time

import machine
import micropython
import rigcore

PIN_SCK, PIN_MOSI, PIN_CS = 18, 19, 17
PIN_MONITOR_ADC = 26
PIN_ESTOP = 15
PIN_HX_DOUT, PIN_HX_SCK = 4, 5
HX711_TIMEOUT_MS = 200


class PicoHardware:
    """The real pins behind :class:`rigcore.Controller`."""

    def __init__(self):
        self.spi = machine.SPI(0, baudrate=1000000, polarity=0, phase=0,
                               sck=machine.Pin(PIN_SCK), mosi=machine.Pin(PIN_MOSI))
        self.cs = machine.Pin(PIN_CS, machine.Pin.OUT, value=1)
        self.adc = machine.ADC(PIN_MONITOR_ADC)
        self.estop = machine.Pin(PIN_ESTOP, machine.Pin.IN, machine.Pin.PULL_UP)
        self.hx_dout = machine.Pin(PIN_HX_DOUT, machine.Pin.IN)
        self.hx_sck = machine.Pin(PIN_HX_SCK, machine.Pin.OUT, value=0)
        self.pressed_latch = False
        # the interrupt latches a press even if the main loop is busy (e.g. reading the HX711)
        self.estop.irq(trigger=machine.Pin.IRQ_FALLING, handler=self._on_press)

    def _on_press(self, pin):
        self.pressed_latch = True
        # vent at once from the interrupt: the DAC write is short and allocation-free
        self.cs.value(0)
        self.spi.write(b"\x30\x00")  # rigcore.mcp4921_frame(0)
        self.cs.value(1)

    def write_dac(self, frame):
        self.cs.value(0)
        self.spi.write(frame)
        self.cs.value(1)

    def read_monitor_u16(self):
        total = 0
        for _ in range(8):
            total += self.adc.read_u16()
        return total // 8

    def estop_pressed(self):
        latched = self.pressed_latch
        self.pressed_latch = False
        return latched or self.estop.value() == 0

    def read_load_counts(self):
        start = time.ticks_ms()
        while self.hx_dout.value() == 1:  # data ready when DOUT goes low
            if time.ticks_diff(time.ticks_ms(), start) > HX711_TIMEOUT_MS:
                return None
        raw = 0
        for _ in range(24):
            self.hx_sck.value(1)
            self.hx_sck.value(0)
            raw = (raw << 1) | self.hx_dout.value()
        self.hx_sck.value(1)  # 25th pulse: channel A, gain 128 for the next reading
        self.hx_sck.value(0)
        return rigcore.hx711_signed(raw)


def main():
    micropython.kbd_intr(-1)  # a stray 0x03 byte on the wire must not stop the firmware
    controller = rigcore.Controller(PicoHardware())
    poller = select.poll()
    poller.register(sys.stdin, select.POLLIN)
    buf = ""
    last_command = time.ticks_ms()
    while True:
        for line in controller.poll(time.ticks_diff(time.ticks_ms(), last_command)):
            sys.stdout.write(line + "\n")
        if poller.poll(5):
            ch = sys.stdin.read(1)
            if ch == "\n":
                last_command = time.ticks_ms()
                for line in controller.handle(buf):
                    sys.stdout.write(line + "\n")
                buf = ""
            elif len(buf) <= rigcore.MAX_LINE:
                buf += ch
            # longer lines keep growing no further; they get ERR PARSE at the newline


main()
