"""Scene generators: the book's tables as Python data, written out as rt70 URDF files.

The data live in :mod:`rt70.scenes.rt70_data` (the RT-70 listing of §4.2.3 and the
chapter-2 tables) and :mod:`rt70.scenes.mechanisms` (small test mechanisms);
:mod:`rt70.scenes.rt70_scenes`, :mod:`rt70.scenes.book_scenes` and
:mod:`rt70.scenes.loop_scenes` write them as scenes with :mod:`rt70.scenes.urdf_writer`,
and :mod:`rt70.scenes.generate` writes the URDF files under ``urdf/``
(``python -m rt70.scenes.generate [DIR]``).
What the analyses are told about the RT-70 is built here too:
:mod:`rt70.scenes.rt70_chapter2` (the chapter-2 models from the tables) and
:mod:`rt70.scenes.rt70_state` (pointing axes, the listing's start state).
"""
