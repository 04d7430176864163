"""gtecat: an EtherCAT master emulator with the Googol GT_* motion API on top."""

__version__ = "0.1.0"
