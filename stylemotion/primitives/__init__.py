"""Motion primitives (Du §4.3, §5.2): foot contacts (:mod:`.contacts`), segmentation of takes into stance
clips and canonical timelines (:mod:`.segmentation`), foot skating (:mod:`.skating`) and the segmentation
report of ``stylemotion-segment`` (:mod:`.report`). Importing the package loads none of them."""
