"""The documentation: the CLI page, the generated figures, the stated-number rule, the README
front page and the links of every page (the site build itself is ``make docs``)."""
