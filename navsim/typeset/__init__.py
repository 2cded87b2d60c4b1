"""The report toolkit every kind's report is built with: the Typst document and its escaping
(:mod:`~navsim.typeset.document`), the figures (:mod:`~navsim.typeset.figures`), numbers
(:mod:`~navsim.typeset.statistics`) and sections (:mod:`~navsim.typeset.sections`) the kinds share, and
reading run and campaign directories (:mod:`~navsim.typeset.inputs`). Which report a directory gets is
:mod:`navsim.report`'s."""
