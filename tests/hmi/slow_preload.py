"""A module whose import never ends: the fork server that preloads it stands for one still importing the HMI's
workers' modules on a machine too busy to give it the processor (it ends when it is killed)."""

import signal

signal.pause()
