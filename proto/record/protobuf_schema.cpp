#include "proto/record/protobuf_schema.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>

#include <set>

#include "common/util/error.h"

namespace cohaptic::record {
namespace {

// Depth first, dependencies before the file itself: a topological order of the imports.
void add_file(const google::protobuf::FileDescriptor* file,
              std::set<const google::protobuf::FileDescriptor*>& seen,
              google::protobuf::FileDescriptorSet& set) {
  if (!seen.insert(file).second) return;
  for (int i = 0; i < file->dependency_count(); ++i) add_file(file->dependency(i), seen, set);
  file->CopyTo(set.add_file());
}

}  // namespace

std::string protobuf_schema_data(const google::protobuf::Descriptor* descriptor) {
  if (descriptor == nullptr) throw Error("protobuf_schema_data: no message descriptor");
  google::protobuf::FileDescriptorSet set;
  std::set<const google::protobuf::FileDescriptor*> seen;
  add_file(descriptor->file(), seen, set);
  return set.SerializeAsString();
}

std::string schema_name(const google::protobuf::Descriptor* descriptor) {
  if (descriptor == nullptr) throw Error("schema_name: no message descriptor");
  return descriptor->full_name();
}

}  // namespace cohaptic::record
