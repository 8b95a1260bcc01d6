// ContactModel: how a tool holds the surface it touches. One vocabulary for the scene files,
// the server's IR builder, the wire and the haptic loop's evaluator, so this header includes
// nothing of the project's.
#pragma once

namespace cohaptic {

/// The paper's two (node translation of the contact triangle, the contact point alone) and
/// the sphere model (every node a sphere tool has passed, held on its surface;
/// common/contact/sphere_contact.h), the default for sphere tools.
enum class ContactModel { node_translation, point_constraint, sphere };

/// The scene file's name of a contact model.
inline const char* contact_model_name(ContactModel model) {
  return model == ContactModel::node_translation   ? "translation"
         : model == ContactModel::point_constraint ? "point"
                                                   : "sphere";
}

}  // namespace cohaptic
