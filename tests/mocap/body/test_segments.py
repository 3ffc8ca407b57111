"""Joint names of real rigs onto the 15 body segments (mocap.body.segments)."""
from __future__ import annotations

import re

import numpy as np
import pytest

from mocap.body.retarget import reduce_to_segments
from mocap.body.segments import BODY_SEGMENTS, map_segments, read_joint_map, words
from mocap.errors import MocapError
from mocap.skeleton import Motion, Skeleton


def tree(spec: str) -> tuple[list[str], list[int]]:
    """Names and parents from ``a(b c(d))``; names are separated by commas."""
    names: list[str] = []
    parents: list[int] = []
    stack = [-1]
    for token in re.findall(r"[^(),]+|[(),]", spec):
        if token == "(":
            stack.append(len(names) - 1)
        elif token == ")":
            stack.pop()
        elif token != "," and token.strip():
            names.append(token.strip())
            parents.append(stack[-1])
    return names, parents


def side_rig(left: str, right: str, spell) -> str:
    """A CMU-like rig with limb names spelled by ``spell(side, base)``."""
    def arm(s):
        return (f"{spell(s, 'Shoulder')}({spell(s, 'UpperArm')}({spell(s, 'ForeArm')}"
                f"({spell(s, 'Hand')}({spell(s, 'HandIndex1')}))))")

    def leg(s):
        return f"{spell(s, 'UpLeg')}({spell(s, 'Leg')}({spell(s, 'Foot')}({spell(s, 'ToeBase')})))"
    return (f"Hips({leg(left)},{leg(right)},Spine(Spine1(Spine2(Neck(Head(HeadTop_End)),"
            f"{arm(left)},{arm(right)}))))")


SPELLINGS = {
    "Left…": lambda s, b: f"{'Left' if s == 'l' else 'Right'}{b}",
    "L_…": lambda s, b: f"{s.upper()}_{b}",
    "…_L": lambda s, b: f"{b}_{s.upper()}",
    "….L": lambda s, b: f"{b}.{s.upper()}",
    "…_l": lambda s, b: f"{b.lower()}_{s}",
    "…Left": lambda s, b: f"{b}{'Left' if s == 'l' else 'Right'}",
    "l…": lambda s, b: f"{s}{b.lower()}",
    "Left_…": lambda s, b: f"{'left' if s == 'l' else 'right'}_{b.lower()}",
}
EXPECTED_SPELLED = {"pelvis": "Hips", "thorax": "Spine2", "head": "Head",
                    "upperarm": "UpperArm", "forearm": "ForeArm", "hand": "Hand",
                    "thigh": "UpLeg", "shank": "Leg", "foot": "Foot"}


@pytest.mark.parametrize("style", sorted(SPELLINGS))
def test_side_prefixes_and_suffixes_in_any_spelling(style):
    spell = SPELLINGS[style]
    names, parents = tree(side_rig("l", "r", spell))
    found = {s: names[i] for s, i in map_segments(names, parents).items()}
    expected = {}
    for segment in BODY_SEGMENTS:
        base = EXPECTED_SPELLED[segment[2:] if segment[1] == "_" else segment]
        expected[segment] = spell(segment[0], base) if segment[1] == "_" else base
    assert found == expected


RIGS = {
    "mixamo": ("mixamorig:Hips(mixamorig:Spine(mixamorig:Spine1(mixamorig:Spine2("
               "mixamorig:Neck(mixamorig:Head(mixamorig:HeadTop_End)),"
               "mixamorig:LeftShoulder(mixamorig:LeftArm(mixamorig:LeftForeArm("
               "mixamorig:LeftHand(mixamorig:LeftHandIndex1)))),"
               "mixamorig:RightShoulder(mixamorig:RightArm(mixamorig:RightForeArm("
               "mixamorig:RightHand))))))," 
               "mixamorig:LeftUpLeg(mixamorig:LeftLeg(mixamorig:LeftFoot(mixamorig:LeftToeBase))),"
               "mixamorig:RightUpLeg(mixamorig:RightLeg(mixamorig:RightFoot)))",
               " ".join("mixamorig:" + n for n in "Hips Spine2 Head LeftArm LeftForeArm LeftHand "
                        "LeftUpLeg LeftLeg LeftFoot".split())),
    "cmu_bvh": ("Hips(LHipJoint(LeftUpLeg(LeftLeg(LeftFoot(LeftToeBase)))),"
                "RHipJoint(RightUpLeg(RightLeg(RightFoot(RightToeBase)))),"
                "LowerBack(Spine(Spine1(Neck(Neck1(Head)),"
                "LeftShoulder(LeftArm(LeftForeArm(LeftHand(LeftFingerBase,LThumb)))),"
                "RightShoulder(RightArm(RightForeArm(RightHand(RightFingerBase,RThumb))))))))",
                "Hips Spine1 Head LeftArm LeftForeArm LeftHand LeftUpLeg LeftLeg LeftFoot"),
    "cmu_hdm05_asf": ("root(lhipjoint(lfemur(ltibia(lfoot(ltoes)))),rhipjoint(rfemur(rtibia("
                      "rfoot(rtoes)))),lowerback(upperback(thorax(lowerneck(upperneck(head)),"
                      "lclavicle(lhumerus(lradius(lwrist(lhand(lfingers),lthumb)))),"
                      "rclavicle(rhumerus(rradius(rwrist(rhand(rfingers),rthumb))))))))",
                      "root thorax head lhumerus lradius lhand lfemur ltibia lfoot"),
    "unreal": ("root(pelvis(spine_01(spine_02(spine_03(clavicle_l(upperarm_l(lowerarm_l("
               "hand_l),lowerarm_twist_01_l),upperarm_twist_01_l),clavicle_r(upperarm_r("
               "lowerarm_r(hand_r))),neck_01(head)))),thigh_l(calf_l(foot_l(ball_l),"
               "calf_twist_01_l),thigh_twist_01_l),thigh_r(calf_r(foot_r(ball_r)))))",
               "pelvis spine_03 head upperarm_l lowerarm_l hand_l thigh_l calf_l foot_l"),
    "rigify": ("DEF-spine(DEF-spine.001(DEF-spine.002(DEF-spine.003(DEF-spine.004("
               "DEF-spine.005(DEF-spine.006)),DEF-shoulder.L(DEF-upper_arm.L("
               "DEF-upper_arm.L.001(DEF-forearm.L(DEF-forearm.L.001(DEF-hand.L))))),"
               "DEF-shoulder.R(DEF-upper_arm.R(DEF-upper_arm.R.001(DEF-forearm.R("
               "DEF-forearm.R.001(DEF-hand.R)))))))),DEF-pelvis.L,DEF-pelvis.R,"
               "DEF-thigh.L(DEF-thigh.L.001(DEF-shin.L(DEF-shin.L.001(DEF-foot.L(DEF-toe.L))))),"
               "DEF-thigh.R(DEF-thigh.R.001(DEF-shin.R(DEF-shin.R.001(DEF-foot.R(DEF-toe.R))))))",
               "DEF-spine DEF-spine.003 DEF-spine.006 DEF-upper_arm.L DEF-forearm.L DEF-hand.L "
               "DEF-thigh.L DEF-shin.L DEF-foot.L"),
    "bandai": ("joint_Root(Hips(Spine(Chest(Neck(Head),Shoulder_L(UpperArm_L(LowerArm_L("
               "Hand_L))),Shoulder_R(UpperArm_R(LowerArm_R(Hand_R))))),UpperLeg_L(LowerLeg_L("
               "Foot_L(Toes_L))),UpperLeg_R(LowerLeg_R(Foot_R(Toes_R)))))",
               "Hips Chest Head UpperArm_L LowerArm_L Hand_L UpperLeg_L LowerLeg_L Foot_L"),
    "biped": ("Bip01(Bip01 Pelvis(Bip01 Spine(Bip01 L Thigh(Bip01 L Calf(Bip01 L Foot("
              "Bip01 L Toe0))),Bip01 R Thigh(Bip01 R Calf(Bip01 R Foot)),Bip01 Spine1("
              "Bip01 Neck(Bip01 Head,Bip01 L Clavicle(Bip01 L UpperArm(Bip01 L Forearm("
              "Bip01 L Hand))),Bip01 R Clavicle(Bip01 R UpperArm(Bip01 R Forearm("
              "Bip01 R Hand))))))))",
              "Bip01 Pelvis|Bip01 Neck|Bip01 Head|Bip01 L UpperArm|Bip01 L Forearm|"
              "Bip01 L Hand|Bip01 L Thigh|Bip01 L Calf|Bip01 L Foot"),
    "humanik": ("Character1_Hips(Character1_LeftUpLeg(Character1_LeftLeg(Character1_LeftFoot)),"
                "Character1_RightUpLeg(Character1_RightLeg(Character1_RightFoot)),"
                "Character1_Spine(Character1_Spine1(Character1_LeftShoulder(Character1_LeftArm("
                "Character1_LeftForeArm(Character1_LeftHand))),Character1_RightShoulder("
                "Character1_RightArm(Character1_RightForeArm(Character1_RightHand))),"
                "Character1_Neck(Character1_Head))))",
                " ".join("Character1_" + n for n in "Hips Spine1 Head LeftArm LeftForeArm "
                         "LeftHand LeftUpLeg LeftLeg LeftFoot".split())),
    "unity": ("Hips(LeftUpperLeg(LeftLowerLeg(LeftFoot(LeftToes))),RightUpperLeg(RightLowerLeg("
              "RightFoot)),Spine(Chest(UpperChest(LeftShoulder(LeftUpperArm(LeftLowerArm("
              "LeftHand))),RightShoulder(RightUpperArm(RightLowerArm(RightHand))),Neck(Head)))))",
              "Hips UpperChest Head LeftUpperArm LeftLowerArm LeftHand LeftUpperLeg LeftLowerLeg "
              "LeftFoot"),
}
LEFT = ["pelvis", "thorax", "head", "l_upperarm", "l_forearm", "l_hand", "l_thigh", "l_shank",
        "l_foot"]


@pytest.mark.parametrize("rig", sorted(RIGS))
def test_real_rig_conventions_map_onto_the_body(rig):
    spec, expected = RIGS[rig]
    names, parents = tree(spec)
    found = {s: names[i] for s, i in map_segments(names, parents).items()}
    assert set(found) == set(BODY_SEGMENTS)
    sep = "|" if "|" in expected else " "
    wanted = expected.split(sep)
    assert [found[s] for s in LEFT] == wanted
    # The right side mirrors the left.
    for s in LEFT[3:]:
        right = found["r" + s[1:]]
        assert right != found[s] and right in names


def test_words_split_namespaces_case_and_separators():
    assert words("mixamorig:LeftUpLeg") == ["left", "up", "leg"]
    assert words("Bip01 L Thigh") == ["l", "thigh"]
    assert words("DEF-upper_arm.L.001") == ["upper", "arm", "l", "001"]
    assert words("LHipJoint") == ["l", "hip"]


def _chain_motion(names, parents):
    offsets = np.tile([0.0, 0.1, 0.0], (len(names), 1))
    sk = Skeleton(names, parents, offsets)
    return Motion.still(sk, 2, 30.0)


def test_unmappable_rig_says_what_was_found_and_missing_and_a_joint_map_fixes_it(tmp_path):
    names, parents = tree("b0(b1(b2(b3),b4(b5(b6)),b7(b8(b9))),b10(b11(b12)),b13(b14(b15)))")
    motion = _chain_motion(names, parents)
    motion.metadata["source"] = "rig.bvh"
    with pytest.raises(MocapError) as error:
        reduce_to_segments(motion)
    text = str(error.value)
    assert text.startswith("rig.bvh: cannot map") and "\n" not in text
    assert "missing thorax, head, l_upperarm" in text and "found pelvis=b0" in text
    assert "b15" in text and "joint_map=" in text
    mapping = tmp_path / "rig.toml"
    mapping.write_text("\n".join(f'{s} = "b{i}"' for s, i in zip(
        BODY_SEGMENTS, [0, 1, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15])) + "\n")
    joint_map = read_joint_map(mapping)
    body = reduce_to_segments(motion, joint_map=joint_map)
    assert body.names == BODY_SEGMENTS
    assert body.metadata["segment_map"]["l_thigh"] == "b10"
    # Partial maps: the rest is found by name; bad maps are one clear line.
    for text, message in [('l_thigh = "nosuch"\n', "no such joint"),
                          ('left_leg = "b1"\n', "not a body segment"),
                          ("l_thigh = 3\n", "joint name in quotes"),
                          ("l_thigh = \n", "not valid TOML")]:
        mapping.write_text(text)
        with pytest.raises(MocapError, match=message):
            reduce_to_segments(motion, joint_map=read_joint_map(mapping))
