"""ballbat: oblique ball-bat collisions, from impacts to e_x, eta^2 and batted-ball flight.

Reproduces Kensrud, Nathan & Smith, "Oblique Collisions of Baseballs and Softballs with a
Bat", Am. J. Phys. 85, 503 (2017). Importing the package is deliberately cheap: every
module imports only what it needs, so that workflow jobs start fast.
"""

__version__ = "0.2.0"
