// What Gazebo's URDF parser keeps of a URDF: load it with libsdformat (sdf::Root::Load, the
// parser of Gazebo Fortress with Debian's sdformat 12) and print, one line each,
//   ERROR <message>
//   LINK <name> <mass> <ixx> <ixy> <ixz> <iyy> <iyz> <izz> <com x> <com y> <com z>
//   JOINT <name> <type> <parent> <child> <axis x> <axis y> <axis z> <lower> <upper> <effort>
//         <velocity> <damping> <friction>
//   FRAME <name> <attached to> <x> <y> <z> <roll> <pitch> <yaw>   (its pose in the link it is attached to)
//   MIMIC <number of <mimic> elements in the converted SDFormat>
// Inertias are about the centre of mass, in the link frame; the centre of mass is in the link
// frame. Built and run by tests/test_gazebo.py.
#include <iostream>
#include <sstream>
#include <string>

#include <sdf/sdf.hh>

namespace {
int count(const std::string &text, const std::string &word) {
  int n = 0;
  for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++n;
  return n;
}
}  // namespace

int main(int argc, char **argv) {
  if (argc != 2) {
    std::cerr << "usage: sdformat_probe FILE.urdf\n";
    return 2;
  }
  sdf::Root root;
  sdf::Errors errors = root.Load(argv[1]);
  for (const auto &error : errors) std::cout << "ERROR " << error.Message() << "\n";
  std::cout.precision(17);
  const sdf::Model *model = root.Model();
  if (model == nullptr) return 0;
  for (uint64_t i = 0; i < model->LinkCount(); ++i) {
    const sdf::Link *link = model->LinkByIndex(i);
    const auto &inertial = link->Inertial();
    const auto &moi = inertial.Moi();
    const auto &com = inertial.Pose().Pos();
    std::cout << "LINK " << link->Name() << " " << inertial.MassMatrix().Mass() << " " << moi(0, 0) << " "
              << moi(0, 1) << " " << moi(0, 2) << " " << moi(1, 1) << " " << moi(1, 2) << " " << moi(2, 2)
              << " " << com.X() << " " << com.Y() << " " << com.Z() << "\n";
  }
  for (uint64_t i = 0; i < model->JointCount(); ++i) {
    const sdf::Joint *joint = model->JointByIndex(i);
    std::cout << "JOINT " << joint->Name() << " " << static_cast<int>(joint->Type()) << " "
              << joint->ParentLinkName() << " " << joint->ChildLinkName();
    const sdf::JointAxis *axis = joint->Axis(0);
    if (axis != nullptr) {
      const auto &xyz = axis->Xyz();
      std::cout << " " << xyz.X() << " " << xyz.Y() << " " << xyz.Z() << " " << axis->Lower() << " "
                << axis->Upper() << " " << axis->Effort() << " " << axis->MaxVelocity() << " "
                << axis->Damping() << " " << axis->Friction();
    }
    std::cout << "\n";
  }
  for (uint64_t i = 0; i < model->FrameCount(); ++i) {
    const sdf::Frame *frame = model->FrameByIndex(i);
    std::string link;
    frame->ResolveAttachedToBody(link);
    ignition::math::Pose3d pose;
    frame->SemanticPose().Resolve(pose, link);
    std::cout << "FRAME " << frame->Name() << " " << link << " " << pose.Pos().X() << " " << pose.Pos().Y() << " "
              << pose.Pos().Z() << " " << pose.Rot().Roll() << " " << pose.Rot().Pitch() << " " << pose.Rot().Yaw()
              << "\n";
  }
  std::cout << "MIMIC " << count(root.Element()->ToString(""), "<mimic") << "\n";
  return 0;
}
