"""feederkit: orient and recognize flat parts with push-align operations and partial sensing.

The theory is Akella & Mason, "Using Partial Sensor Information to Orient Parts" (IJRR 1999).
"""

__version__ = "0.1.0"
