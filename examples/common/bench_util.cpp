#include "common/bench_util.h"

std::vector<std::string> SplitList(const std::string &s)
{
  std::vector<std::string> out;
  size_t                   start = 0;
  while (start <= s.size()) {
    size_t end = s.find(',', start);
    if (end == std::string::npos) end = s.size();
    if (end > start) out.push_back(s.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

std::string LastErrorText()
{
  const char *text     = nullptr;
  char       *specific = nullptr;
  PetscErrorMessage(PETSC_ERR_SUP, &text, &specific);
  std::string s = specific ? specific : (text ? text : "error");
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}
