"""python -m stereo_servo: the host command, safe from a stray host.py in the working folder."""

import sys

from stereo_servo import main

sys.exit(main())
