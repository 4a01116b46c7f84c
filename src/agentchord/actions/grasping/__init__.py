"""Where a grasp's fingers, tool and wrist go: the planning helpers of the arm programs.

The programs (``actions.grasp``, ``place``, ``move``) ask these modules where to put the hand;
none of them runs the arm itself (they may plan a joint-space move for a program to make).
One concept a module: the tool's shared geometry (``geometry``), where open fingers clear
their neighbours (``finger_clearance``), a side grasp's poses (``side_plan``), a top grasp's
(``top_grasp``), a fallen object's grasp and turn upright (``fallen_turn``), what the hand
already holds (``in_hand``), the wrist's branches (``wrist_branch``), an object dragged clear of
a rim (``drag_clear``), one put down flat (``tip_flat``), and the other arm stepping back
(``make_way``).
"""
